#include "demLib/version.hpp"

namespace dem {
// Exported so that applications can check at run time which library they loaded.
const char* libraryVersion() { return versionString; }
}  // namespace dem
