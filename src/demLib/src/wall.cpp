#include "demLib/wall.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

namespace dem {

void Wall::findContacts(const Vec3& centre, double radius, double time, std::vector<WallContact>& out) const {
    if (!isActive(time)) {
        return;
    }
    findContacts(centre, radius, time, motion.isStatic() ? RigidTransform{} : motion.at(time), out);
}

void Wall::findContacts(const Vec3& centre, double radius, double time, const RigidTransform& pose,
                        std::vector<WallContact>& out) const {
    findContactsWith(centre, time, pose, out, [&](const Vec3& reference) {
        std::visit([&](const auto& surface) { surface.findContacts(reference, radius, out); }, shape);
    });
}

void Wall::findContactsAmong(const Vec3& centre, double radius, double time, const RigidTransform& pose,
                             const int* triangles, int count, std::vector<WallContact>& out) const {
    const auto* mesh = std::get_if<MeshWall>(&shape);
    if (!mesh) {
        findContacts(centre, radius, time, pose, out);
        return;
    }
    findContactsWith(centre, time, pose, out, [&](const Vec3& reference) {
        mesh->mesh().findContactsAmong(reference, radius, triangles, count, out);
    });
}

void Wall::nearTriangles(const Vec3& centre, double radius, double time, std::vector<int>& out) const {
    const auto* mesh = std::get_if<MeshWall>(&shape);
    if (!mesh || !isActive(time)) return;
    mesh->mesh().nearTriangles(motion.isStatic() ? centre : motion.at(time).applyInverse(centre), radius, out);
}

template <class Search>
void Wall::findContactsWith(const Vec3& centre, double time, const RigidTransform& pose,
                            std::vector<WallContact>& out, Search&& search) const {
    if (motion.isStatic()) {
        search(centre);
        return;  // wall velocity stays zero
    }
    const std::size_t firstNew = out.size();
    search(pose.applyInverse(centre));
    for (std::size_t i = firstNew; i < out.size(); ++i) {
        WallContact& contact = out[i];
        contact.normal = pose.applyToDirection(contact.normal);
        contact.point = pose.apply(contact.point);
        contact.wallVelocity = motion.velocityAt(contact.point, time);
    }
}

namespace {

// Corner k (0-7) of the box [lower, upper]: bit 0 picks x, bit 1 y, bit 2 z.
Vec3 boxCorner(const Vec3& lower, const Vec3& upper, int k) {
    return Vec3((k & 1) ? upper.x() : lower.x(), (k & 2) ? upper.y() : lower.y(), (k & 4) ? upper.z() : lower.z());
}

// Box of a reference-frame box after a rigid transform: enclose its eight corners.
BoundingBox transformed(const BoundingBox& box, const RigidTransform& pose) {
    if (box.isUnbounded() || box.isEmpty()) {
        return box;
    }
    BoundingBox result;
    for (int corner = 0; corner < 8; ++corner) result.expand(pose.apply(boxCorner(box.lower, box.upper, corner)));
    return result;
}

double distanceFromAxis(const Vec3& point, const Vec3& axisPoint, const Vec3& unitAxis) {
    const Vec3 d = point - axisPoint;
    return (d - d.dot(unitAxis) * unitAxis).norm();
}

double farthestCornerFromAxis(const Vec3& lower, const Vec3& upper, const Vec3& axisPoint, const Vec3& unitAxis) {
    double farthest = 0.0;
    for (int corner = 0; corner < 8; ++corner)
        farthest = std::max(farthest, distanceFromAxis(boxCorner(lower, upper, corner), axisPoint, unitAxis));
    return farthest;
}

}  // namespace

double Wall::largestSpeed(std::size_t k, const AxisAlignedBox* domain) const {
    const MotionSegment& segment = motion.segments().at(k);
    if (!isActive(segment.tStart)) return 0.0;
    if (segment.kind == MotionSegment::Kind::Translate) return segment.velocity.norm();
    // A point's distance from the axis stays while the wall turns about it:
    // take the wall where the segment starts.
    const Vec3& axisPoint = segment.axisPoint;
    const Vec3& axis = segment.axisDirection;
    double reach = std::numeric_limits<double>::infinity();
    if (const auto* mesh = std::get_if<MeshWall>(&shape)) {
        const RigidTransform pose = motion.at(segment.tStart);
        reach = 0.0;
        for (const Vec3& vertex : mesh->mesh().vertices())
            reach = std::max(reach, distanceFromAxis(pose.apply(vertex), axisPoint, axis));
    } else if (std::holds_alternative<CylinderWall>(shape)) {
        const BoundingBox box = boundingBox(segment.tStart);
        reach = farthestCornerFromAxis(box.lower, box.upper, axisPoint, axis);
    }
    if (domain) reach = std::min(reach, farthestCornerFromAxis(domain->min, domain->max, axisPoint, axis));
    return std::abs(segment.angularVelocity) * reach;
}

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
    return transformed(referenceBoundingBox(), pose);
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
