#pragma once
// The vector type of demLib: a plain 3-vector of doubles (24 bytes, no alignment
// requirement), so that std::vector<Vec3> is a packed structure-of-arrays field.
#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products

namespace dem {
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
}  // namespace dem
