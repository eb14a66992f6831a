#include "demLib/wall_plane.hpp"

#include <sstream>

#include "demLib/error.hpp"

namespace dem {

PlaneWall::PlaneWall(const Vec3& point, const Vec3& normal) : point_(point), normal_(normal) {
    const double length = normal.norm();
    if (!point.allFinite() || !normal.allFinite() || !(length > 0.0)) {
        std::ostringstream s;
        s << "plane wall: point (" << point.transpose() << ") and normal (" << normal.transpose()
          << "); expected a finite point and a finite non-zero normal";
        throw InputError(s.str());
    }
    normal_ /= length;
}

void PlaneWall::findContacts(const Vec3& centre, double radius, std::vector<WallContact>& out) const {
    const double distance = signedDistance(centre);
    if (distance < 0.0 || distance >= radius) {
        return;
    }
    WallContact contact;
    contact.normal = normal_;
    contact.overlap = radius - distance;
    contact.point = centre - distance * normal_;
    contact.feature = 0;
    out.push_back(contact);
}

}  // namespace dem
