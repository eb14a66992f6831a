#pragma once
// The lateral surface of a finite circular cylinder (a tube without end caps):
// the die wall, the feeding shoe, the repose-angle cylinder.  Geometry: a point
// on the axis, the unit axis, the radius and the axial range [zMin, zMax]
// measured along the axis from that point.
//
// Side::Inside: particles live inside the tube; Side::Outside: outside it.  The
// lateral surface is one-sided like PlaneWall: a centre on the wrong side of
// the surface is not in contact.  The two rim circles (at zMin: feature 1, at
// zMax: feature 2) are edges and touch a sphere from any side once its centre
// lies beyond the axial range; the lateral surface is feature 0.  Bottoms and
// lids are planes or meshes.
#include <vector>

#include "demLib/vec3.hpp"
#include "demLib/wall_contact.hpp"

namespace dem {

class CylinderWall {
public:
    enum class Side { Inside, Outside };

    static constexpr int lateralFeature = 0;
    static constexpr int lowerRimFeature = 1;  // circle at zMin
    static constexpr int upperRimFeature = 2;  // circle at zMax

    // Throws InputError for a zero axis, radius <= 0, zMax <= zMin or
    // non-finite values.  The axis is normalised.
    CylinderWall(const Vec3& axisPoint, const Vec3& axisDirection, double radius, double zMin, double zMax,
                 Side side);

    const Vec3& axisPoint() const { return axisPoint_; }
    const Vec3& axisDirection() const { return axis_; }
    double radius() const { return radius_; }
    double zMin() const { return zMin_; }
    double zMax() const { return zMax_; }
    Side side() const { return side_; }

    // Appends the contacts (at most one: lateral or one rim) with zero wall velocity.
    void findContacts(const Vec3& centre, double radius, std::vector<WallContact>& out) const;

    // Exact axis-aligned box of the finite tube.
    BoundingBox boundingBox() const;

private:
    Vec3 axisPoint_;
    Vec3 axis_;
    double radius_;
    double zMin_;
    double zMax_;
    Side side_;
};

}  // namespace dem
