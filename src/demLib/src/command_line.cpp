#include "demLib/command_line.hpp"

#include <cmath>
#include <cstdlib>

namespace dem {

bool parseNumber(const std::string& text, double& value) {
    if (text.empty()) return false;
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (*end != '\0' || !std::isfinite(v)) return false;
    value = v;
    return true;
}

}  // namespace dem
