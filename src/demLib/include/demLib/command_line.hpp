#pragma once
// Values given on the command line of the demLib tools (demRun, demBench,
// demStability, demCapillaryScaling).
#include <string>

namespace dem {

// The whole of `text` as a finite number: false for "", "2x", "abc" or
// "inf" (atof and atoi read "2x" as 2 and "abc" as 0 without a word).
bool parseNumber(const std::string& text, double& value);

}  // namespace dem
