#pragma once
// The vector type of demLib: a plain 3-vector of doubles (24 bytes, no alignment
// requirement), so that std::vector<Vec3> is a packed structure-of-arrays field.
#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products

// Forces inlining of the small contact-law functions into the force loop: GCC
// otherwise keeps ContactLaw::evaluate out of line (called through the PLT of
// the shared library, its result returned through memory).
#if defined(__GNUC__)
#define DEM_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define DEM_ALWAYS_INLINE inline
#endif

namespace dem {
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
}  // namespace dem
