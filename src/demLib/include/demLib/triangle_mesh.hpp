#pragma once
// Triangulated wall surfaces (feeding shoe, die, inclined plate, any STL part):
// reading STL, sphere-surface contacts with faces, edges and vertices, and a
// point-in-solid test for closed meshes.
//
// Contacts are two-sided (a thin plate is touched from both sides).  One
// contact is reported per touched surface feature, and only where the contact
// point is a local minimum of the distance from the sphere centre to the whole
// surface: an edge (vertex) point counts only when it is also the closest point
// of every triangle sharing that edge (vertex).  This drops the spurious edge
// contacts of convex and coplanar neighbours and keeps genuine ones (concave
// corners give one face contact per face).  See docs/walls.md.
//
// Feature ids (stable while a sphere slides, for contact history):
//   face of triangle t ............ 4 t           (t = lowest triangle of its coplanar patch,
//                                                   so a flat plate made of many triangles has ONE id)
//   edge k (0 AB, 1 BC, 2 CA) ..... 4 t + 1 + k   (t = lowest triangle sharing the edge)
//   vertex v ....................... 4 T + v       (T = number of triangles)
// Edges and vertices inside a coplanar patch are not features: they map to the patch's face id.
#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "demLib/vec3.hpp"
#include "demLib/wall_contact.hpp"

namespace dem {

// Closest point of triangle (a, b, c) to p, with the Voronoi region it lies in
// (Ericson, Real-Time Collision Detection, section 5.1.5).
struct TriangleClosestPoint {
    enum class Region { Face, Edge, Vertex };
    Vec3 point;
    Region region;
    int index;  // Edge: 0 = AB, 1 = BC, 2 = CA.  Vertex: 0 = a, 1 = b, 2 = c.  Face: 0.
};
TriangleClosestPoint closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

using Triangle = std::array<Vec3, 3>;

// Reads an STL file, ASCII or binary (detected: binary whenever the size is
// 84 + 50 n with n the count in the header, even if the header starts with
// "solid"), and multiplies every coordinate by `scale`.  Facet normals in the
// file are ignored: orientation comes from the vertex order.  Throws InputError
// naming the file (and line, for ASCII) when it is missing, unreadable,
// malformed or holds no triangle.
std::vector<Triangle> readStl(const std::string& path, double scale = 1.0);

class TriangleMesh {
public:
    // Builds the mesh from a triangle soup.  Vertices closer than 1e-9 of the
    // bounding-box diagonal are welded; zero-area triangles are dropped (so
    // triangle indices are those of the kept triangles, in input order).
    // `sourceName` names the origin in error messages.  Throws InputError when
    // no triangle with non-zero area is left or a coordinate is not finite.
    explicit TriangleMesh(const std::vector<Triangle>& triangles, const std::string& sourceName = "triangle mesh");
    static TriangleMesh fromStl(const std::string& path, double scale = 1.0);

    std::size_t triangleCount() const { return triangleVertices_.size(); }
    std::size_t vertexCount() const { return vertices_.size(); }
    Triangle triangle(std::size_t t) const;
    const std::vector<Vec3>& vertices() const { return vertices_; }
    const std::vector<std::array<int, 3>>& triangleVertices() const { return triangleVertices_; }
    // Unit normal from the vertex order (right-hand rule).
    const Vec3& faceNormal(std::size_t t) const { return faceNormals_[t]; }
    BoundingBox boundingBox() const { return box_; }

    int faceFeature(std::size_t t) const { return faceFeature_[t]; }
    int edgeFeature(std::size_t t, int localEdge) const { return edgeFeature_[triangleEdges_[t][localEdge]]; }
    int vertexFeature(std::size_t v) const { return vertexFeature_[v]; }

    // Appends one contact per touched feature (zero wall velocity).  Cost is
    // independent of the mesh size: only triangles in the grid cells overlapped
    // by the sphere's box are tested.
    void findContacts(const Vec3& centre, double radius, std::vector<WallContact>& out) const;
    // The same over the given triangles only: the contacts are those of
    // findContacts whenever the list holds every triangle within `radius` of
    // the centre (nearTriangles of a larger sphere around it).
    void findContactsAmong(const Vec3& centre, double radius, const int* triangles, int count,
                           std::vector<WallContact>& out) const;
    // Appends the triangles whose surface lies within `radius` of the centre
    // (ascending; a few more within the welding tolerance).
    void nearTriangles(const Vec3& centre, double radius, std::vector<int>& out) const;
    // How many triangles a query for this sphere tests (diagnostics, tests).
    std::size_t candidateCount(const Vec3& centre, double radius) const;

    // Whether the mesh bounds a solid: every edge is shared by an even number
    // of triangles (no open border).  containsPoint means something only then.
    bool isClosed() const { return closed_; }
    // Point-in-solid for a closed mesh: parity of ray crossings, majority vote
    // over three fixed skew rays so that a ray grazing an edge or a vertex
    // cannot flip the answer.  Each ray walks the triangle grid, so the cost
    // follows the grid cells it crosses; meant for set-up (insertion regions,
    // checking inserted particles), not for the time loop.
    bool containsPoint(const Vec3& p) const;
    // The three unit ray directions containsPoint casts (tests aim them at edges).
    static const std::array<Vec3, 3>& parityRays();

private:
    struct Grid {
        Vec3 origin = Vec3::Zero();
        double cellSize = 1.0;
        std::array<int, 3> dims{1, 1, 1};
        std::vector<int> cellStart;                  // CSR offsets, size cells + 1
        std::vector<int> cellTriangles;              // triangle ids per cell
        std::vector<std::array<int, 3>> firstCell;   // per triangle: lowest cell of its box
    };
    void weld(const std::vector<Triangle>& triangles, const std::string& sourceName);
    void buildTopology();
    void buildGrid();
    std::array<int, 3> cellOf(const Vec3& p) const;
    // True when every triangle in `neighbours` has its closest point to
    // `centre` at `point` (within the welding tolerance).
    bool isClosestForAll(const Vec3& centre, const Vec3& point, const int* neighbours, int count) const;
    template <class Visit>
    void forEachCandidate(const Vec3& centre, double radius, Visit&& visit) const;
    // Whether the sphere can touch triangle t: its plane and box within reach.
    bool mayTouch(int t, const Vec3& centre, double reach) const;
    template <class ForEachTriangle>
    void contactsFrom(const Vec3& centre, double radius, ForEachTriangle&& forEachTriangle,
                      std::vector<WallContact>& out) const;

    std::vector<Vec3> vertices_;
    std::vector<std::array<int, 3>> triangleVertices_;
    std::vector<Vec3> faceNormals_;
    // Per triangle, for rejecting far candidates before the closest-point
    // search: the plane's offset (normal . a) and the triangle's box.
    std::vector<double> planeOffsets_;
    std::vector<BoundingBox> triangleBoxes_;
    BoundingBox box_;
    double tolerance_ = 0.0;
    bool closed_ = false;

    // Topology.
    std::vector<std::array<int, 3>> triangleEdges_;  // edge id of local edges AB, BC, CA
    std::vector<int> edgeTriangleStart_, edgeTriangles_;      // CSR: triangles sharing each edge
    std::vector<int> vertexTriangleStart_, vertexTriangles_;  // CSR: triangles around each vertex
    std::vector<int> faceFeature_, edgeFeature_, vertexFeature_;

    Grid grid_;
};

// The wall shape that dem::Wall holds: a shared, immutable mesh (copying a Wall
// does not copy the triangles).
class MeshWall {
public:
    explicit MeshWall(std::shared_ptr<const TriangleMesh> mesh);
    const TriangleMesh& mesh() const { return *mesh_; }
    void findContacts(const Vec3& centre, double radius, std::vector<WallContact>& out) const {
        mesh_->findContacts(centre, radius, out);
    }
    BoundingBox boundingBox() const { return mesh_->boundingBox(); }
    // Shared, so that a copy of the wall keeps pointing at the same triangles.
    const std::shared_ptr<const TriangleMesh>& sharedMesh() const { return mesh_; }

private:
    std::shared_ptr<const TriangleMesh> mesh_;
};

}  // namespace dem
