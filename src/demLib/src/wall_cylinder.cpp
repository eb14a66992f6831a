#include "demLib/wall_cylinder.hpp"

#include <cmath>
#include <sstream>

#include <Eigen/Geometry>

#include "demLib/error.hpp"

namespace dem {

namespace {

// Any unit vector perpendicular to the unit vector `axis`.
Vec3 anyPerpendicular(const Vec3& axis) {
    const Vec3 helper = std::abs(axis.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
    return axis.cross(helper).normalized();
}

}  // namespace

CylinderWall::CylinderWall(const Vec3& axisPoint, const Vec3& axisDirection, double radius, double zMin,
                           double zMax, Side side)
    : axisPoint_(axisPoint), axis_(axisDirection), radius_(radius), zMin_(zMin), zMax_(zMax), side_(side) {
    const double length = axisDirection.norm();
    const bool finite = axisPoint.allFinite() && axisDirection.allFinite() && std::isfinite(radius) &&
                        std::isfinite(zMin) && std::isfinite(zMax);
    if (!finite || !(length > 0.0) || !(radius > 0.0) || !(zMax > zMin)) {
        std::ostringstream s;
        s << "cylinder wall: axis point (" << axisPoint.transpose() << "), axis (" << axisDirection.transpose()
          << "), radius " << radius << ", axial range [" << zMin << ", " << zMax
          << "]; expected finite values, a non-zero axis, radius > 0 and zMax > zMin";
        throw InputError(s.str());
    }
    axis_ /= length;
}

void CylinderWall::findContacts(const Vec3& centre, double radius, std::vector<WallContact>& out) const {
    const Vec3 fromAxisPoint = centre - axisPoint_;
    const double z = fromAxisPoint.dot(axis_);
    const Vec3 radial = fromAxisPoint - z * axis_;
    // Most particles are clearly far from the surface: say so from squares,
    // before the root and the division below (the walls of a die or shoe are
    // queried for every particle at every step).  The margin of 1e-12 is far
    // above rounding, so this returns only where the exact test below would.
    const double rho2 = radial.squaredNorm();
    constexpr double up = 1.0 + 1e-12, down = 1.0 - 1e-12;
    if (z >= zMin_ && z <= zMax_) {
        const double near = radius_ - radius, far = radius_ + radius;  // |rho - R| < radius
        const double radius2 = radius_ * radius_;
        if (side_ == Side::Inside ? rho2 > radius2 * up || (near > 0.0 && rho2 < near * near * down)
                                  : rho2 < radius2 * down || rho2 > far * far * up)
            return;
    } else {
        const double axial = z < zMin_ ? zMin_ - z : z - zMax_;  // the rim is at least this far
        if (axial * axial > radius * radius * up) return;
    }
    const double rho = std::sqrt(rho2);
    // Unit radial direction; on the axis every direction is equally close.
    const Vec3 radialUnit = rho > 0.0 ? Vec3(radial / rho) : anyPerpendicular(axis_);

    WallContact contact;
    if (z >= zMin_ && z <= zMax_) {
        const double distance = side_ == Side::Inside ? radius_ - rho : rho - radius_;
        if (distance < 0.0 || distance >= radius) {
            return;  // too far, or the centre is behind the (one-sided) surface
        }
        contact.normal = side_ == Side::Inside ? Vec3(-radialUnit) : radialUnit;
        contact.overlap = radius - distance;
        contact.point = axisPoint_ + z * axis_ + radius_ * radialUnit;
        contact.feature = lateralFeature;
        out.push_back(contact);
        return;
    }
    // Beyond the axial range: the nearest surface point is on the nearer rim circle.
    const bool below = z < zMin_;
    const double zRim = below ? zMin_ : zMax_;
    const Vec3 rimPoint = axisPoint_ + zRim * axis_ + radius_ * radialUnit;
    const Vec3 fromRim = centre - rimPoint;
    const double distance = fromRim.norm();
    if (distance >= radius || !(distance > 0.0)) {
        return;
    }
    contact.normal = fromRim / distance;
    contact.overlap = radius - distance;
    contact.point = rimPoint;
    contact.feature = below ? lowerRimFeature : upperRimFeature;
    out.push_back(contact);
}

BoundingBox CylinderWall::boundingBox() const {
    // A circle of radius R with unit normal a spans R * sqrt(1 - a_i^2) along axis i.
    const Vec3 halfExtent = radius_ * (Vec3::Ones() - axis_.cwiseAbs2()).cwiseMax(0.0).cwiseSqrt();
    BoundingBox box;
    for (double zEnd : {zMin_, zMax_}) {
        const Vec3 endCentre = axisPoint_ + zEnd * axis_;
        box.expand(endCentre - halfExtent);
        box.expand(endCentre + halfExtent);
    }
    return box;
}

}  // namespace dem
