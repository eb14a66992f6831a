#pragma once
// An infinite plane wall, given by a point and the unit normal that points
// into the domain (towards the particles).
//
// One-sided on purpose: a sphere touches the plane only while its centre is on
// the normal side (0 <= signed distance < radius).  A particle whose centre has
// crossed to the back is NOT in contact (it would otherwise be pushed through
// the plane, not back).  A wall that particles may touch from both sides, or a
// plate of finite size, is a triangle mesh.
#include <vector>

#include "demLib/vec3.hpp"
#include "demLib/wall_contact.hpp"

namespace dem {

class PlaneWall {
public:
    // Throws InputError when the normal is zero or a value is not finite; the
    // normal is normalised.
    PlaneWall(const Vec3& point, const Vec3& normal);

    const Vec3& point() const { return point_; }
    const Vec3& normal() const { return normal_; }

    // Signed distance of `p` from the plane, positive on the normal side.
    double signedDistance(const Vec3& p) const { return (p - point_).dot(normal_); }

    // Appends the contact (feature 0) of a sphere, with zero wall velocity.
    void findContacts(const Vec3& centre, double radius, std::vector<WallContact>& out) const;

    BoundingBox boundingBox() const { return BoundingBox::unbounded(); }

private:
    Vec3 point_;
    Vec3 normal_;
};

}  // namespace dem
