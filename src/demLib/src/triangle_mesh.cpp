#include "demLib/triangle_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <unordered_map>
#include <utility>

#include <Eigen/Geometry>

#include "demLib/error.hpp"

namespace dem {

// ---------------------------------------------------------------- closest point

TriangleClosestPoint closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
    using Region = TriangleClosestPoint::Region;
    // Ericson's region tests: barycentric conditions evaluated with dot products only.
    const Vec3 ab = b - a;
    const Vec3 ac = c - a;
    const Vec3 ap = p - a;
    const double d1 = ab.dot(ap);
    const double d2 = ac.dot(ap);
    if (d1 <= 0.0 && d2 <= 0.0) {
        return {a, Region::Vertex, 0};
    }
    const Vec3 bp = p - b;
    const double d3 = ab.dot(bp);
    const double d4 = ac.dot(bp);
    if (d3 >= 0.0 && d4 <= d3) {
        return {b, Region::Vertex, 1};
    }
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        return {a + (d1 / (d1 - d3)) * ab, Region::Edge, 0};
    }
    const Vec3 cp = p - c;
    const double d5 = ab.dot(cp);
    const double d6 = ac.dot(cp);
    if (d6 >= 0.0 && d5 <= d6) {
        return {c, Region::Vertex, 2};
    }
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        return {a + (d2 / (d2 - d6)) * ac, Region::Edge, 2};
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        return {b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b), Region::Edge, 1};
    }
    const double inverse = 1.0 / (va + vb + vc);
    return {a + ab * (vb * inverse) + ac * (vc * inverse), Region::Face, 0};
}

// ---------------------------------------------------------------- STL reading

namespace {

std::string stlError(const std::string& path, const std::string& what) {
    return "STL file '" + path + "': " + what;
}

std::uint32_t littleEndianU32(const unsigned char* bytes) {
    return std::uint32_t(bytes[0]) | (std::uint32_t(bytes[1]) << 8) | (std::uint32_t(bytes[2]) << 16) |
           (std::uint32_t(bytes[3]) << 24);
}

float littleEndianFloat(const unsigned char* bytes) {
    const std::uint32_t bits = littleEndianU32(bytes);
    float value;
    std::memcpy(&value, &bits, sizeof value);
    return value;
}

std::vector<Triangle> readBinaryStl(const std::string& path, const std::string& content, std::uint32_t count,
                                    double scale) {
    std::vector<Triangle> triangles(count);
    const auto* data = reinterpret_cast<const unsigned char*>(content.data());
    for (std::uint32_t t = 0; t < count; ++t) {
        // Record: normal (3 floats), 3 vertices (9 floats), attribute (uint16).
        const unsigned char* record = data + 84 + std::size_t(t) * 50;
        for (int corner = 0; corner < 3; ++corner) {
            for (int axis = 0; axis < 3; ++axis) {
                const double value = littleEndianFloat(record + 12 + 12 * corner + 4 * axis);
                if (!std::isfinite(value)) {
                    throw InputError(stlError(path, "binary triangle " + std::to_string(t) +
                                                        " has a non-finite coordinate; expected finite numbers"));
                }
                triangles[t][corner][axis] = value * scale;
            }
        }
    }
    return triangles;
}

// Whitespace tokens with the line they are on.
class AsciiTokens {
public:
    AsciiTokens(const std::string& path, const std::string& content) : path_(path), text_(content) {}

    bool atEnd() {
        skipSpace();
        return position_ >= text_.size();
    }
    std::string next(const char* expected) {
        if (atEnd()) {
            throw InputError(stlError(path_, "line " + std::to_string(line_) + ": unexpected end of file; expected " +
                                                 expected));
        }
        const std::size_t start = position_;
        while (position_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[position_]))) {
            ++position_;
        }
        return text_.substr(start, position_ - start);
    }
    void expect(const char* keyword) {
        const std::string token = next(keyword);
        if (token != keyword) {
            fail(std::string("expected '") + keyword + "', found '" + token + "'");
        }
    }
    double number(const char* what) {
        const std::string token = next(what);
        char* end = nullptr;
        const double value = std::strtod(token.c_str(), &end);
        if (end != token.c_str() + token.size() || !std::isfinite(value)) {
            fail(std::string("expected ") + what + " (a finite number), found '" + token + "'");
        }
        return value;
    }
    void skipRestOfLine() {
        while (position_ < text_.size() && text_[position_] != '\n') {
            ++position_;
        }
    }
    [[noreturn]] void fail(const std::string& what) const {
        throw InputError(stlError(path_, "line " + std::to_string(line_) + ": " + what));
    }

private:
    void skipSpace() {
        while (position_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[position_]))) {
            if (text_[position_] == '\n') {
                ++line_;
            }
            ++position_;
        }
    }
    const std::string& path_;
    const std::string& text_;
    std::size_t position_ = 0;
    int line_ = 1;
};

std::vector<Triangle> readAsciiStl(const std::string& path, const std::string& content, double scale) {
    AsciiTokens tokens(path, content);
    std::vector<Triangle> triangles;
    // solid [name] { facet normal nx ny nz  outer loop  vertex x y z (x3)  endloop  endfacet } endsolid [name]
    while (!tokens.atEnd()) {
        tokens.expect("solid");
        tokens.skipRestOfLine();  // the solid's name
        for (;;) {
            const std::string token = tokens.next("'facet' or 'endsolid'");
            if (token == "endsolid") {
                tokens.skipRestOfLine();
                break;
            }
            if (token != "facet") {
                tokens.fail("expected 'facet' or 'endsolid', found '" + token + "'");
            }
            tokens.expect("normal");
            for (int axis = 0; axis < 3; ++axis) {
                tokens.number("a facet normal component");
            }
            tokens.expect("outer");
            tokens.expect("loop");
            Triangle triangle;
            for (int corner = 0; corner < 3; ++corner) {
                tokens.expect("vertex");
                for (int axis = 0; axis < 3; ++axis) {
                    triangle[corner][axis] = tokens.number("a vertex coordinate") * scale;
                }
            }
            const std::string closing = tokens.next("'endloop'");
            if (closing == "vertex") {
                tokens.fail("facet " + std::to_string(triangles.size()) +
                            " has more than 3 vertices; expected triangles only");
            }
            if (closing != "endloop") {
                tokens.fail("expected 'endloop', found '" + closing + "'");
            }
            tokens.expect("endfacet");
            triangles.push_back(triangle);
        }
    }
    return triangles;
}

}  // namespace

std::vector<Triangle> readStl(const std::string& path, double scale) {
    if (!std::isfinite(scale) || !(scale > 0.0)) {
        std::ostringstream s;
        s << "scale factor " << scale << "; expected a finite number > 0";
        throw InputError(stlError(path, s.str()));
    }
    std::ifstream file(path, std::ios::binary);
    if (!file) {
        throw InputError(stlError(path, "cannot be opened (missing or unreadable); expected an ASCII or binary STL file"));
    }
    const std::string content((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    if (file.bad()) {
        throw InputError(stlError(path, "read error"));
    }

    const std::size_t size = content.size();
    std::vector<Triangle> triangles;
    bool binary = false;
    std::uint64_t announced = 0;
    if (size >= 84) {
        announced = littleEndianU32(reinterpret_cast<const unsigned char*>(content.data()) + 80);
        binary = 84 + 50 * announced == size;
    }
    if (binary) {
        triangles = readBinaryStl(path, content, static_cast<std::uint32_t>(announced), scale);
    } else {
        const std::size_t firstWord = content.find_first_not_of(" \t\r\n");
        if (firstWord != std::string::npos && content.compare(firstWord, 5, "solid") == 0) {
            triangles = readAsciiStl(path, content, scale);
        } else if (size < 84) {
            throw InputError(stlError(path, "is " + std::to_string(size) +
                                                " bytes long and does not start with 'solid'; expected an ASCII "
                                                "STL or a binary STL (at least 84 bytes)"));
        } else {
            throw InputError(stlError(
                path, "does not start with 'solid' (so it is not ASCII STL) and its size " + std::to_string(size) +
                          " bytes differs from the 84 + 50 * " + std::to_string(announced) + " = " +
                          std::to_string(84 + 50 * announced) +
                          " bytes that its binary header announces (truncated or corrupt binary STL)"));
        }
    }
    if (triangles.empty()) {
        throw InputError(stlError(path, "contains no triangles; expected at least one facet"));
    }
    return triangles;
}

// ---------------------------------------------------------------- mesh building

namespace {

// Two faces sharing an edge belong to one flat patch when their normals differ
// by less than this angle (radians).  Generous enough for float32 STL
// coordinates, far below the facet angle of any tessellated curve.
constexpr double coplanarAngle = 1e-5;
// Vertices closer than this fraction of the bounding-box diagonal are one vertex.
constexpr double relativeWeldTolerance = 1e-9;

struct CellKey {
    std::int64_t i, j, k;
    bool operator==(const CellKey& o) const { return i == o.i && j == o.j && k == o.k; }
};
struct CellKeyHash {
    std::size_t operator()(const CellKey& key) const {
        return std::size_t(key.i * 73856093) ^ std::size_t(key.j * 19349663) ^ std::size_t(key.k * 83492791);
    }
};

int findRoot(std::vector<int>& parent, int i) {
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

}  // namespace

TriangleMesh::TriangleMesh(const std::vector<Triangle>& triangles, const std::string& sourceName) {
    weld(triangles, sourceName);
    buildTopology();
    buildGrid();
    // Closed: every edge bounds an even number of triangles (two on a
    // manifold; four where two solids share an edge), so every ray crosses
    // the surface an even number of times and containsPoint's parity holds.
    closed_ = true;
    for (std::size_t e = 0; e + 1 < edgeTriangleStart_.size(); ++e) {
        if ((edgeTriangleStart_[e + 1] - edgeTriangleStart_[e]) % 2 != 0) {
            closed_ = false;
            break;
        }
    }
}

TriangleMesh TriangleMesh::fromStl(const std::string& path, double scale) {
    return TriangleMesh(readStl(path, scale), "STL file '" + path + "'");
}

Triangle TriangleMesh::triangle(std::size_t t) const {
    const auto& v = triangleVertices_[t];
    return {vertices_[v[0]], vertices_[v[1]], vertices_[v[2]]};
}

void TriangleMesh::weld(const std::vector<Triangle>& triangles, const std::string& sourceName) {
    for (std::size_t t = 0; t < triangles.size(); ++t) {
        for (const Vec3& corner : triangles[t]) {
            if (!corner.allFinite()) {
                throw InputError(sourceName + ": triangle " + std::to_string(t) +
                                 " has a non-finite coordinate; expected finite numbers");
            }
            box_.expand(corner);
        }
    }
    if (triangles.empty()) {
        throw InputError(sourceName + ": has no triangles; expected at least one");
    }
    tolerance_ = relativeWeldTolerance * (box_.upper - box_.lower).norm();
    const double cell = tolerance_ > 0.0 ? tolerance_ : 1.0;

    // Hash on cells of the tolerance size; a vertex merges with the first
    // earlier vertex within tolerance in its own or a neighbouring cell.
    std::unordered_map<CellKey, std::vector<int>, CellKeyHash> buckets;
    auto vertexId = [&](const Vec3& p) {
        const CellKey key{std::int64_t(std::floor((p.x() - box_.lower.x()) / cell)),
                          std::int64_t(std::floor((p.y() - box_.lower.y()) / cell)),
                          std::int64_t(std::floor((p.z() - box_.lower.z()) / cell))};
        for (std::int64_t di = -1; di <= 1; ++di) {
            for (std::int64_t dj = -1; dj <= 1; ++dj) {
                for (std::int64_t dk = -1; dk <= 1; ++dk) {
                    const auto found = buckets.find({key.i + di, key.j + dj, key.k + dk});
                    if (found == buckets.end()) {
                        continue;
                    }
                    for (int id : found->second) {
                        if ((vertices_[id] - p).norm() <= tolerance_) {
                            return id;
                        }
                    }
                }
            }
        }
        vertices_.push_back(p);
        buckets[key].push_back(int(vertices_.size()) - 1);
        return int(vertices_.size()) - 1;
    };

    for (const Triangle& triangle : triangles) {
        const std::array<int, 3> ids{vertexId(triangle[0]), vertexId(triangle[1]), vertexId(triangle[2])};
        if (ids[0] == ids[1] || ids[1] == ids[2] || ids[2] == ids[0]) {
            continue;  // collapsed by welding
        }
        const Vec3 a = vertices_[ids[0]], b = vertices_[ids[1]], c = vertices_[ids[2]];
        const Vec3 doubleArea = (b - a).cross(c - a);
        const double longestEdge2 = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
        if (!(doubleArea.norm() > 1e-12 * longestEdge2)) {
            continue;  // zero area: carries no surface
        }
        triangleVertices_.push_back(ids);
        faceNormals_.push_back(doubleArea.normalized());
        planeOffsets_.push_back(faceNormals_.back().dot(a));
        BoundingBox box;
        box.expand(a);
        box.expand(b);
        box.expand(c);
        triangleBoxes_.push_back(box);
    }
    if (triangleVertices_.empty()) {
        throw InputError(sourceName + ": all " + std::to_string(triangles.size()) +
                         " triangles have zero area; expected a surface");
    }
}

void TriangleMesh::buildTopology() {
    const int triangleCount = int(triangleVertices_.size());
    const int vertexCount = int(vertices_.size());

    // Edges: a map from the sorted vertex pair.
    std::unordered_map<std::uint64_t, int> edgeOfPair;
    std::vector<std::vector<int>> trianglesOfEdge;
    triangleEdges_.resize(triangleCount);
    for (int t = 0; t < triangleCount; ++t) {
        for (int k = 0; k < 3; ++k) {
            const int v0 = triangleVertices_[t][k];
            const int v1 = triangleVertices_[t][(k + 1) % 3];
            const std::uint64_t key = (std::uint64_t(std::min(v0, v1)) << 32) | std::uint64_t(std::max(v0, v1));
            const auto inserted = edgeOfPair.emplace(key, int(trianglesOfEdge.size()));
            if (inserted.second) {
                trianglesOfEdge.emplace_back();
            }
            triangleEdges_[t][k] = inserted.first->second;
            trianglesOfEdge[inserted.first->second].push_back(t);
        }
    }
    const int edgeCount = int(trianglesOfEdge.size());
    edgeTriangleStart_.assign(1, 0);
    for (const auto& list : trianglesOfEdge) {
        edgeTriangles_.insert(edgeTriangles_.end(), list.begin(), list.end());
        edgeTriangleStart_.push_back(int(edgeTriangles_.size()));
    }

    // Triangles around each vertex (CSR).
    vertexTriangleStart_.assign(vertexCount + 1, 0);
    for (const auto& tv : triangleVertices_) {
        for (int v : tv) {
            ++vertexTriangleStart_[v + 1];
        }
    }
    for (int v = 0; v < vertexCount; ++v) {
        vertexTriangleStart_[v + 1] += vertexTriangleStart_[v];
    }
    vertexTriangles_.resize(vertexTriangleStart_.back());
    std::vector<int> fill(vertexTriangleStart_.begin(), vertexTriangleStart_.end() - 1);
    for (int t = 0; t < triangleCount; ++t) {
        for (int v : triangleVertices_[t]) {
            vertexTriangles_[fill[v]++] = t;
        }
    }

    // Flat edges: exactly two triangles, (anti)parallel normals, and lying on
    // opposite sides of the edge (a folded-back fin is not flat).
    std::vector<char> edgeIsFlat(edgeCount, 0);
    const double coplanarCosine = std::cos(coplanarAngle);
    std::vector<int> parent(triangleCount);
    for (int t = 0; t < triangleCount; ++t) {
        parent[t] = t;
    }
    for (int e = 0; e < edgeCount; ++e) {
        const auto& list = trianglesOfEdge[e];
        if (list.size() != 2) {
            continue;
        }
        const int t1 = list[0], t2 = list[1];
        if (std::abs(faceNormals_[t1].dot(faceNormals_[t2])) < coplanarCosine) {
            continue;
        }
        auto oppositeVertex = [&](int t) {
            for (int k = 0; k < 3; ++k) {
                if (triangleEdges_[t][k] == e) {
                    return vertices_[triangleVertices_[t][(k + 2) % 3]];
                }
            }
            return vertices_[triangleVertices_[t][0]];  // unreachable: t holds edge e
        };
        int k1 = 0;
        while (triangleEdges_[t1][k1] != e) {
            ++k1;
        }
        const Vec3 p = vertices_[triangleVertices_[t1][k1]];
        const Vec3 direction = (vertices_[triangleVertices_[t1][(k1 + 1) % 3]] - p).normalized();
        auto across = [&](const Vec3& o) {
            const Vec3 w = o - p;
            return Vec3(w - w.dot(direction) * direction);
        };
        if (across(oppositeVertex(t1)).dot(across(oppositeVertex(t2))) >= 0.0) {
            continue;
        }
        edgeIsFlat[e] = 1;
        parent[findRoot(parent, t1)] = findRoot(parent, t2);
    }

    // Patch representative: its lowest triangle index.
    std::vector<int> lowestOfRoot(triangleCount, triangleCount);
    for (int t = 0; t < triangleCount; ++t) {
        const int root = findRoot(parent, t);
        lowestOfRoot[root] = std::min(lowestOfRoot[root], t);
    }
    faceFeature_.resize(triangleCount);
    for (int t = 0; t < triangleCount; ++t) {
        faceFeature_[t] = 4 * lowestOfRoot[findRoot(parent, t)];
    }
    edgeFeature_.resize(edgeCount);
    for (int e = 0; e < edgeCount; ++e) {
        const int owner = *std::min_element(trianglesOfEdge[e].begin(), trianglesOfEdge[e].end());
        int k = 0;
        while (triangleEdges_[owner][k] != e) {
            ++k;
        }
        edgeFeature_[e] = edgeIsFlat[e] ? faceFeature_[owner] : 4 * owner + 1 + k;
    }
    // A vertex is a feature unless all its edges are flat within one patch.
    vertexFeature_.resize(vertexCount);
    for (int v = 0; v < vertexCount; ++v) {
        bool flat = vertexTriangleStart_[v + 1] > vertexTriangleStart_[v];
        const int patch = flat ? faceFeature_[vertexTriangles_[vertexTriangleStart_[v]]] : -1;
        for (int i = vertexTriangleStart_[v]; i < vertexTriangleStart_[v + 1] && flat; ++i) {
            const int t = vertexTriangles_[i];
            flat = faceFeature_[t] == patch;
            for (int k = 0; k < 3 && flat; ++k) {
                const int a = triangleVertices_[t][k], b = triangleVertices_[t][(k + 1) % 3];
                if ((a == v || b == v) && !edgeIsFlat[triangleEdges_[t][k]]) {
                    flat = false;
                }
            }
        }
        vertexFeature_[v] = flat ? patch : 4 * triangleCount + v;
    }
}

void TriangleMesh::buildGrid() {
    const int triangleCount = int(triangleVertices_.size());
    // Cell size: the mean largest extent of the triangles' boxes, enlarged if
    // the grid would hold more than a few cells per triangle.
    double meanExtent = 0.0;
    for (int t = 0; t < triangleCount; ++t) {
        BoundingBox box;
        for (int v : triangleVertices_[t]) {
            box.expand(vertices_[v]);
        }
        meanExtent += (box.upper - box.lower).maxCoeff();
    }
    meanExtent /= triangleCount;
    const Vec3 extent = box_.upper - box_.lower;
    const double maxCells = std::max(64.0, 8.0 * triangleCount);
    double cellSize = std::max(meanExtent, 1e-6 * extent.maxCoeff());
    for (;;) {
        const Eigen::Array3d cells = (extent / cellSize).array().ceil().max(1.0);
        if (cells.prod() <= maxCells) {
            for (int axis = 0; axis < 3; ++axis) {
                grid_.dims[axis] = int(cells[axis]);
            }
            break;
        }
        cellSize *= std::cbrt(cells.prod() / maxCells) * 1.01;
    }
    grid_.origin = box_.lower;
    grid_.cellSize = cellSize;

    const std::size_t cellCount = std::size_t(grid_.dims[0]) * grid_.dims[1] * grid_.dims[2];
    grid_.firstCell.resize(triangleCount);
    std::vector<std::array<int, 3>> lastCell(triangleCount);
    std::vector<int> counts(cellCount + 1, 0);
    auto cellIndex = [&](int i, int j, int k) { return (std::size_t(k) * grid_.dims[1] + j) * grid_.dims[0] + i; };
    for (int pass = 0; pass < 2; ++pass) {
        std::vector<int> fill;
        if (pass == 1) {
            for (std::size_t c = 0; c < cellCount; ++c) {
                counts[c + 1] += counts[c];
            }
            grid_.cellStart = counts;
            grid_.cellTriangles.resize(counts.back());
            fill.assign(counts.begin(), counts.end() - 1);
        }
        for (int t = 0; t < triangleCount; ++t) {
            if (pass == 0) {
                BoundingBox box;
                for (int v : triangleVertices_[t]) {
                    box.expand(vertices_[v]);
                }
                grid_.firstCell[t] = cellOf(box.lower);
                lastCell[t] = cellOf(box.upper);
            }
            const auto& lo = grid_.firstCell[t];
            const auto& hi = lastCell[t];
            for (int k = lo[2]; k <= hi[2]; ++k) {
                for (int j = lo[1]; j <= hi[1]; ++j) {
                    for (int i = lo[0]; i <= hi[0]; ++i) {
                        if (pass == 0) {
                            ++counts[cellIndex(i, j, k) + 1];
                        } else {
                            grid_.cellTriangles[fill[cellIndex(i, j, k)]++] = t;
                        }
                    }
                }
            }
        }
    }
}

std::array<int, 3> TriangleMesh::cellOf(const Vec3& p) const {
    std::array<int, 3> cell;
    for (int axis = 0; axis < 3; ++axis) {
        const double index = std::floor((p[axis] - grid_.origin[axis]) / grid_.cellSize);
        cell[axis] = int(std::clamp(index, 0.0, double(grid_.dims[axis] - 1)));
    }
    return cell;
}

// ---------------------------------------------------------------- queries

template <class Visit>
void TriangleMesh::forEachCandidate(const Vec3& centre, double radius, Visit&& visit) const {
    if (!box_.overlapsSphere(centre, radius)) {
        return;
    }
    const std::array<int, 3> lo = cellOf(centre - Vec3::Constant(radius));
    const std::array<int, 3> hi = cellOf(centre + Vec3::Constant(radius));
    for (int k = lo[2]; k <= hi[2]; ++k) {
        for (int j = lo[1]; j <= hi[1]; ++j) {
            for (int i = lo[0]; i <= hi[0]; ++i) {
                const std::size_t cell = (std::size_t(k) * grid_.dims[1] + j) * grid_.dims[0] + i;
                for (int n = grid_.cellStart[cell]; n < grid_.cellStart[cell + 1]; ++n) {
                    const int t = grid_.cellTriangles[n];
                    // A triangle spanning several cells is visited only in the
                    // lowest cell shared by its box and the query box.
                    const auto& first = grid_.firstCell[t];
                    if (std::max(first[0], lo[0]) != i || std::max(first[1], lo[1]) != j ||
                        std::max(first[2], lo[2]) != k) {
                        continue;
                    }
                    visit(t);
                }
            }
        }
    }
}

std::size_t TriangleMesh::candidateCount(const Vec3& centre, double radius) const {
    std::size_t count = 0;
    forEachCandidate(centre, radius, [&](int) { ++count; });
    return count;
}

bool TriangleMesh::isClosestForAll(const Vec3& centre, const Vec3& point, const int* neighbours, int count) const {
    for (int n = 0; n < count; ++n) {
        const auto& tv = triangleVertices_[neighbours[n]];
        const Vec3 closest = closestPointOnTriangle(centre, vertices_[tv[0]], vertices_[tv[1]], vertices_[tv[2]]).point;
        if ((closest - point).norm() > tolerance_) {
            return false;
        }
    }
    return true;
}

bool TriangleMesh::mayTouch(int t, const Vec3& centre, double reach) const {
    return std::abs(faceNormals_[t].dot(centre) - planeOffsets_[t]) < reach &&
           triangleBoxes_[t].overlapsSphere(centre, reach);
}

void TriangleMesh::findContacts(const Vec3& centre, double radius, std::vector<WallContact>& out) const {
    contactsFrom(centre, radius, [&](auto&& visit) { forEachCandidate(centre, radius, visit); }, out);
}

void TriangleMesh::findContactsAmong(const Vec3& centre, double radius, const int* triangles, int count,
                                     std::vector<WallContact>& out) const {
    contactsFrom(centre, radius, [&](auto&& visit) { for (int k = 0; k < count; ++k) visit(triangles[k]); }, out);
}

void TriangleMesh::nearTriangles(const Vec3& centre, double radius, std::vector<int>& out) const {
    const std::size_t first = out.size();
    const double reach = radius + tolerance_;
    forEachCandidate(centre, radius, [&](int t) {
        if (!mayTouch(t, centre, reach)) return;
        const auto& tv = triangleVertices_[t];
        const Vec3 closest = closestPointOnTriangle(centre, vertices_[tv[0]], vertices_[tv[1]], vertices_[tv[2]]).point;
        if ((closest - centre).norm() < reach) out.push_back(t);
    });
    std::sort(out.begin() + static_cast<std::ptrdiff_t>(first), out.end());
}

template <class ForEachTriangle>
void TriangleMesh::contactsFrom(const Vec3& centre, double radius, ForEachTriangle&& forEachTriangle,
                                std::vector<WallContact>& out) const {
    using Region = TriangleClosestPoint::Region;
    struct Candidate {
        Vec3 point;
        double distance;
        int feature;
        int rank;  // 0 face, 1 edge, 2 vertex: faces win ties
        int triangle;
    };
    thread_local std::vector<Candidate> candidates;
    candidates.clear();
    const double radius2 = radius * radius;
    // A triangle farther than this from the sphere's centre along its normal,
    // or whose box the sphere misses, cannot be touched.  The welding tolerance
    // keeps every triangle the closest-point test below would take.
    const double rejectBeyond = radius + tolerance_;

    forEachTriangle([&](int t) {
        if (!mayTouch(t, centre, rejectBeyond)) {
            return;
        }
        const auto& tv = triangleVertices_[t];
        const TriangleClosestPoint closest =
            closestPointOnTriangle(centre, vertices_[tv[0]], vertices_[tv[1]], vertices_[tv[2]]);
        const double distance2 = (centre - closest.point).squaredNorm();
        if (distance2 >= radius2) {
            return;
        }
        Candidate candidate{closest.point, std::sqrt(distance2), 0, 0, t};
        if (closest.region == Region::Face) {
            candidate.feature = faceFeature_[t];
        } else if (closest.region == Region::Edge) {
            const int e = triangleEdges_[t][closest.index];
            const int first = edgeTriangleStart_[e];
            if (!isClosestForAll(centre, closest.point, &edgeTriangles_[first], edgeTriangleStart_[e + 1] - first)) {
                return;  // a neighbour is closer: not a local minimum of the distance
            }
            candidate.feature = edgeFeature_[e];
            candidate.rank = 1;
        } else {
            const int v = tv[closest.index];
            const int first = vertexTriangleStart_[v];
            if (!isClosestForAll(centre, closest.point, &vertexTriangles_[first], vertexTriangleStart_[v + 1] - first)) {
                return;
            }
            candidate.feature = vertexFeature_[v];
            candidate.rank = 2;
        }
        candidates.push_back(candidate);
    });

    // Ties broken by triangle: the same contacts whatever order the triangles came in.
    std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
        if (a.rank != b.rank) return a.rank < b.rank;
        if (a.distance != b.distance) return a.distance < b.distance;
        return a.triangle < b.triangle;
    });
    const std::size_t firstNew = out.size();
    for (const Candidate& candidate : candidates) {
        bool duplicate = false;
        for (std::size_t i = firstNew; i < out.size() && !duplicate; ++i) {
            duplicate = out[i].feature == candidate.feature || (out[i].point - candidate.point).norm() <= tolerance_;
        }
        if (duplicate) {
            continue;
        }
        WallContact contact;
        // A centre lying on the surface has no direction to the surface: use the face normal.
        contact.normal = candidate.distance > 1e-12 * radius ? Vec3((centre - candidate.point) / candidate.distance)
                                                             : faceNormals_[candidate.triangle];
        contact.overlap = radius - candidate.distance;
        contact.point = candidate.point;
        contact.feature = candidate.feature;
        out.push_back(contact);
    }
}

const std::array<Vec3, 3>& TriangleMesh::parityRays() {
    // Skew directions: no edge of an axis-aligned or axisymmetric part is
    // parallel to them, and no two are coplanar with a common edge.
    static const std::array<Vec3, 3> rays{Vec3(1.0, 0.3127, 0.1943).normalized(),
                                          Vec3(-0.2713, 1.0, 0.4139).normalized(),
                                          Vec3(0.3571, -0.1789, 1.0).normalized()};
    return rays;
}

namespace {

// Moller-Trumbore: whether the ray p + s d (s > 0) crosses triangle (a, b, c).
bool rayCrossesTriangle(const Vec3& p, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 e1 = b - a;
    const Vec3 e2 = c - a;
    const Vec3 pvec = d.cross(e2);
    const double determinant = e1.dot(pvec);
    if (std::abs(determinant) <= 1e-14 * e1.norm() * e2.norm()) {
        return false;  // ray parallel to the triangle
    }
    const double inverse = 1.0 / determinant;
    const Vec3 tvec = p - a;
    const double u = tvec.dot(pvec) * inverse;
    if (u < 0.0 || u > 1.0) {
        return false;
    }
    const Vec3 qvec = tvec.cross(e1);
    const double v = d.dot(qvec) * inverse;
    if (v < 0.0 || u + v > 1.0) {
        return false;
    }
    return e2.dot(qvec) * inverse > 0.0;
}

}  // namespace


bool TriangleMesh::containsPoint(const Vec3& p) const {
    if (!box_.overlapsSphere(p, 0.0)) {
        return false;
    }
    // Each ray walks the triangle grid cell by cell (Amanatides and Woo) from
    // p's cell to the grid's end, so the cost follows the cells it crosses,
    // not the mesh size.  A triangle is listed in every cell of its box, so a
    // crossing is found in some cell along the ray, possibly in several: the
    // crossed triangles are collected and counted once each.
    std::vector<int> crossed;
    int insideVotes = 0;
    for (const Vec3& direction : parityRays()) {
        crossed.clear();
        std::array<int, 3> cell = cellOf(p);
        std::array<int, 3> step{};
        Vec3 nextBoundary, boundaryStep;  // ray parameter of the next cell face per axis, and between faces
        for (int axis = 0; axis < 3; ++axis) {
            // The parity rays have no zero component.
            step[axis] = direction[axis] > 0.0 ? 1 : -1;
            const double face = grid_.origin[axis] + (cell[axis] + (step[axis] > 0 ? 1 : 0)) * grid_.cellSize;
            nextBoundary[axis] = (face - p[axis]) / direction[axis];
            boundaryStep[axis] = grid_.cellSize / std::abs(direction[axis]);
        }
        for (;;) {
            const std::size_t c = (std::size_t(cell[2]) * grid_.dims[1] + cell[1]) * grid_.dims[0] + cell[0];
            for (int n = grid_.cellStart[c]; n < grid_.cellStart[c + 1]; ++n) {
                const int t = grid_.cellTriangles[n];
                const auto& tv = triangleVertices_[t];
                if (rayCrossesTriangle(p, direction, vertices_[tv[0]], vertices_[tv[1]], vertices_[tv[2]])) {
                    crossed.push_back(t);
                }
            }
            int axis = 0;
            if (nextBoundary[1] < nextBoundary[axis]) axis = 1;
            if (nextBoundary[2] < nextBoundary[axis]) axis = 2;
            cell[axis] += step[axis];
            if (cell[axis] < 0 || cell[axis] >= grid_.dims[axis]) {
                break;
            }
            nextBoundary[axis] += boundaryStep[axis];
        }
        std::sort(crossed.begin(), crossed.end());
        const auto distinct = std::unique(crossed.begin(), crossed.end()) - crossed.begin();
        insideVotes += int(distinct % 2);
    }
    return insideVotes >= 2;
}

// ---------------------------------------------------------------- MeshWall

MeshWall::MeshWall(std::shared_ptr<const TriangleMesh> mesh) : mesh_(std::move(mesh)) {
    if (!mesh_) {
        throw InputError("mesh wall: no mesh given; expected a triangle mesh");
    }
}

}  // namespace dem
