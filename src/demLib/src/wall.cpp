#include "demLib/wall.hpp"

#include <Eigen/Geometry>

namespace dem {

void Wall::findContacts(const Vec3& centre, double radius, double time, std::vector<WallContact>& out) const {
    if (!isActive(time)) {
        return;
    }
    findContacts(centre, radius, time, motion.isStatic() ? RigidTransform{} : motion.at(time), out);
}

void Wall::findContacts(const Vec3& centre, double radius, double time, const RigidTransform& pose,
                        std::vector<WallContact>& out) const {
    if (motion.isStatic()) {
        std::visit([&](const auto& surface) { surface.findContacts(centre, radius, out); }, shape);
        return;  // wall velocity stays zero
    }
    const std::size_t firstNew = out.size();
    const Vec3 referenceCentre = pose.applyInverse(centre);
    std::visit([&](const auto& surface) { surface.findContacts(referenceCentre, radius, out); }, shape);
    for (std::size_t i = firstNew; i < out.size(); ++i) {
        WallContact& contact = out[i];
        contact.normal = pose.applyToDirection(contact.normal);
        contact.point = pose.apply(contact.point);
        contact.wallVelocity = motion.velocityAt(contact.point, time);
    }
}

namespace {

// Box of a reference-frame box after a rigid transform: enclose its eight corners.
BoundingBox transformed(const BoundingBox& box, const RigidTransform& pose) {
    if (box.isUnbounded() || box.isEmpty()) {
        return box;
    }
    BoundingBox result;
    for (int corner = 0; corner < 8; ++corner) {
        const Vec3 p((corner & 1) ? box.upper.x() : box.lower.x(), (corner & 2) ? box.upper.y() : box.lower.y(),
                     (corner & 4) ? box.upper.z() : box.lower.z());
        result.expand(pose.apply(p));
    }
    return result;
}

}  // namespace

BoundingBox Wall::boundingBox(double time) const {
    if (!isActive(time)) {
        return BoundingBox{};  // empty: a removed wall touches nothing
    }
    const RigidTransform pose = motion.at(time);
    if (const auto* cylinder = std::get_if<CylinderWall>(&shape)) {
        // Exact: move the axis, then take the tube's own box.
        const CylinderWall moved(pose.apply(cylinder->axisPoint()), pose.applyToDirection(cylinder->axisDirection()),
                                 cylinder->radius(), cylinder->zMin(), cylinder->zMax(), cylinder->side());
        return moved.boundingBox();
    }
    return std::visit([&](const auto& surface) { return transformed(surface.boundingBox(), pose); }, shape);
}

bool Wall::enclosesPoint(const Vec3& point, double time) const {
    if (!isActive(time)) {
        return false;
    }
    const Vec3 reference = motion.isStatic() ? point : motion.at(time).applyInverse(point);
    if (const auto* plane = std::get_if<PlaneWall>(&shape)) {
        return plane->signedDistance(reference) < 0.0;
    }
    if (const auto* mesh = std::get_if<MeshWall>(&shape)) {
        return mesh->mesh().isClosed() && mesh->mesh().containsPoint(reference);
    }
    return false;
}

}  // namespace dem
