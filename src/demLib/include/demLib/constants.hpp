#pragma once
// Mathematical constants of demLib: one definition for every file.

namespace dem {

inline constexpr double pi = 3.14159265358979323846;

}  // namespace dem
