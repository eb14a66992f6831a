#pragma once
// The wall type the DEM engine loops over: a static shape in its reference
// frame plus a prescribed rigid motion.  A query transforms the sphere centre
// into the reference frame (inverse pose), asks the shape, and maps each
// contact back to the world frame, adding the wall velocity at the contact
// point.  Feature ids are those of the shape, so contact history keyed by
// (particle, wall, feature) survives the motion.
#include <string>
#include <variant>
#include <vector>

#include "demLib/axis_aligned_box.hpp"
#include "demLib/triangle_mesh.hpp"
#include "demLib/vec3.hpp"
#include "demLib/wall_contact.hpp"
#include "demLib/wall_cylinder.hpp"
#include "demLib/wall_motion.hpp"
#include "demLib/wall_plane.hpp"

namespace dem {

using WallShape = std::variant<PlaneWall, CylinderWall, MeshWall>;

struct Wall {
    std::string name;
    WallShape shape;
    WallMotion motion;
    int materialIndex = 0;

    // Appends the contacts of a sphere at world position `centre` at `time`
    // (nothing once the wall is removed).  World-frame normal, point and wall velocity.
    void findContacts(const Vec3& centre, double radius, double time, std::vector<WallContact>& out) const;
    // The same for an active wall whose pose at `time` (motion.at(time)) the
    // caller already has: a moving wall is met by every particle in a step.
    void findContacts(const Vec3& centre, double radius, double time, const RigidTransform& pose,
                      std::vector<WallContact>& out) const;
    // A mesh wall's contacts among the given triangles only (their ids as
    // nearTriangles listed them); any other shape ignores the list.
    void findContactsAmong(const Vec3& centre, double radius, double time, const RigidTransform& pose,
                           const int* triangles, int count, std::vector<WallContact>& out) const;
    // A mesh wall's triangles within `radius` of the sphere centre at `time`
    // (ascending); nothing for any other shape.  Whether it is a mesh: isMesh().
    void nearTriangles(const Vec3& centre, double radius, double time, std::vector<int>& out) const;
    bool isMesh() const { return std::holds_alternative<MeshWall>(shape); }

    // World-frame axis-aligned box enclosing the wall at `time` (unbounded for
    // planes, empty once removed).  A sphere whose box misses it has no
    // contact with this wall.
    BoundingBox boundingBox(double time) const;
    // The shape's own box, in its reference frame (unbounded for a plane).
    BoundingBox referenceBoundingBox() const {
        return std::visit([](const auto& surface) { return surface.boundingBox(); }, shape);
    }
    // Whether a point at `time` lies where no particle centre may be: behind
    // a plane (a one-sided boundary of the half-space in front of it) or
    // inside a closed mesh (a solid part).  A cylinder is a shell of no
    // thickness: particles may be on either side of it (e.g. around a tube).
    bool enclosesPoint(const Vec3& point, double time) const;

    bool isActive(double time) const { return motion.isActive(time); }

    // The largest speed of the wall's material during motion segment k
    // (motion.segments()[k]), 0 if the wall is removed before it starts: |v|
    // for a translation; for a rotation |omega| times the largest distance from
    // the axis of a point of the wall (a mesh's vertices, the corners of a
    // cylinder's box), and no farther than the corners of `domain` when given
    // (particles touch the wall only there).  Infinite for a rotating plane
    // without a domain: its material reaches arbitrarily far.
    double largestSpeed(std::size_t k, const AxisAlignedBox* domain) const;

private:
    // search(reference centre) appends the shape's contacts; this maps the
    // new ones to the world frame of a moving wall.
    template <class Search>
    void findContactsWith(const Vec3& centre, double time, const RigidTransform& pose, std::vector<WallContact>& out,
                          Search&& search) const;
};

}  // namespace dem
