// Wall geometry and prescribed wall motion: every expected value is a closed
// form or an independent brute-force computation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "demLib/error.hpp"
#include "demLib/particle_wall_broad_search.hpp"
#include "demLib/particle_wall_contacts.hpp"
#include "demLib/triangle_mesh.hpp"
#include "demLib/wall.hpp"
#include "demLib/wall_cylinder.hpp"
#include "demLib/wall_motion.hpp"
#include "demLib/wall_plane.hpp"
#include "sand_without_gravity.hpp"

namespace {

using dem::Vec3;
using dem::Triangle;
using dem::WallContact;

constexpr double pi = 3.14159265358979323846;

void expectVectorNear(const Vec3& actual, const Vec3& expected, double tolerance) {
    EXPECT_NEAR((actual - expected).norm(), 0.0, tolerance) << "actual   " << actual.transpose()
                                                            << "\nexpected " << expected.transpose();
}

Vec3 randomUnit(std::mt19937_64& rng) {
    std::normal_distribution<double> normal;
    Vec3 v(normal(rng), normal(rng), normal(rng));
    return v.normalized();
}

// ---------------------------------------------------------------- meshes for the tests

// Axis-aligned box, 12 triangles wound with outward normals; each face is split
// along the diagonal from its lowest corner.
std::vector<Triangle> boxTriangles(const Vec3& lo, const Vec3& hi) {
    auto corner = [&](int i, int j, int k) { return Vec3(i ? hi.x() : lo.x(), j ? hi.y() : lo.y(), k ? hi.z() : lo.z()); };
    std::vector<Triangle> triangles;
    auto quad = [&](const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {  // counter-clockwise seen from outside
        triangles.push_back({a, b, c});
        triangles.push_back({a, c, d});
    };
    quad(corner(0, 0, 0), corner(0, 1, 0), corner(1, 1, 0), corner(1, 0, 0));  // z = lo
    quad(corner(0, 0, 1), corner(1, 0, 1), corner(1, 1, 1), corner(0, 1, 1));  // z = hi
    quad(corner(0, 0, 0), corner(1, 0, 0), corner(1, 0, 1), corner(0, 0, 1));  // y = lo
    quad(corner(0, 1, 0), corner(0, 1, 1), corner(1, 1, 1), corner(1, 1, 0));  // y = hi
    quad(corner(0, 0, 0), corner(0, 0, 1), corner(0, 1, 1), corner(0, 1, 0));  // x = lo
    quad(corner(1, 0, 0), corner(1, 1, 0), corner(1, 1, 1), corner(1, 0, 1));  // x = hi
    return triangles;
}

// Closed regular prism (polygonal cylinder) about the z axis, z in [0, height].
std::vector<Triangle> prismTriangles(double radius, double height, int sides) {
    std::vector<Triangle> triangles;
    for (int k = 0; k < sides; ++k) {
        const double a0 = 2 * pi * k / sides, a1 = 2 * pi * (k + 1) / sides;
        const Vec3 p0(radius * std::cos(a0), radius * std::sin(a0), 0), p1(radius * std::cos(a1), radius * std::sin(a1), 0);
        const Vec3 up(0, 0, height);
        triangles.push_back({p0, p1, p1 + up});
        triangles.push_back({p0, p1 + up, p0 + up});
        triangles.push_back({Vec3(0, 0, 0), p1, p0});
        triangles.push_back({up, p0 + up, p1 + up});
    }
    return triangles;
}

// Square [0, side]^2 at z = 0 made of cells x cells squares, two triangles each.
std::vector<Triangle> squareTriangles(double side, int cells) {
    std::vector<Triangle> triangles;
    const double h = side / cells;
    for (int i = 0; i < cells; ++i) {
        for (int j = 0; j < cells; ++j) {
            const Vec3 a(i * h, j * h, 0), b((i + 1) * h, j * h, 0), c((i + 1) * h, (j + 1) * h, 0), d(i * h, (j + 1) * h, 0);
            triangles.push_back({a, b, c});
            triangles.push_back({a, c, d});
        }
    }
    return triangles;
}

// Unit sphere as a UV mesh: rings x segments, slivers at the poles.
std::vector<Triangle> uvSphereTriangles(int rings, int segments) {
    std::vector<Triangle> triangles;
    auto at = [&](int i, int j) {
        const double theta = pi * i / rings, phi = 2 * pi * j / segments;
        return Vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
    };
    for (int i = 0; i < rings; ++i) {
        for (int j = 0; j < segments; ++j) {
            if (i > 0) triangles.push_back({at(i, j), at(i + 1, j), at(i, j + 1)});
            if (i < rings - 1) triangles.push_back({at(i, j + 1), at(i + 1, j), at(i + 1, j + 1)});
        }
    }
    return triangles;
}

std::vector<WallContact> contactsOf(const dem::TriangleMesh& mesh, const Vec3& centre, double radius) {
    std::vector<WallContact> contacts;
    mesh.findContacts(centre, radius, contacts);
    return contacts;
}

// ---------------------------------------------------------------- STL writers (test side)

class TempDir {
public:
    TempDir() {
        path_ = std::filesystem::temp_directory_path() /
                ("demLib_test_walls_" + std::to_string(std::random_device{}()));
        std::filesystem::create_directories(path_);
    }
    ~TempDir() { std::filesystem::remove_all(path_); }
    std::string file(const std::string& name) const { return (path_ / name).string(); }

private:
    std::filesystem::path path_;
};

// Coordinates as float32, like every binary STL; ASCII prints the float with
// 17 digits so that both files hold the same numbers.
void writeAsciiStl(const std::string& path, const std::vector<Triangle>& triangles) {
    std::FILE* f = std::fopen(path.c_str(), "w");
    std::fprintf(f, "solid test part\n");
    for (const Triangle& t : triangles) {
        const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
        std::fprintf(f, "  facet normal %g %g %g\n    outer loop\n", n.x(), n.y(), n.z());
        for (const Vec3& v : t) {
            std::fprintf(f, "      vertex %.17g %.17g %.17g\n", double(float(v.x())), double(float(v.y())),
                         double(float(v.z())));
        }
        std::fprintf(f, "    endloop\n  endfacet\n");
    }
    std::fprintf(f, "endsolid test part\n");
    std::fclose(f);
}

void writeBinaryStl(const std::string& path, const std::vector<Triangle>& triangles, const std::string& header) {
    std::ofstream f(path, std::ios::binary);
    char head[80] = {};
    std::memcpy(head, header.data(), std::min<std::size_t>(80, header.size()));
    f.write(head, 80);
    const std::uint32_t count = std::uint32_t(triangles.size());
    f.write(reinterpret_cast<const char*>(&count), 4);  // the test machine is little-endian (x86-64)
    for (const Triangle& t : triangles) {
        float record[12] = {};
        for (int c = 0; c < 3; ++c) {
            for (int a = 0; a < 3; ++a) {
                record[3 + 3 * c + a] = float(t[c][a]);
            }
        }
        f.write(reinterpret_cast<const char*>(record), sizeof record);
        const std::uint16_t attribute = 0;
        f.write(reinterpret_cast<const char*>(&attribute), 2);
    }
}

void writeText(const std::string& path, const std::string& text) {
    std::ofstream f(path, std::ios::binary);
    f << text;
}

// Expects readStl(path) to throw InputError whose message contains every fragment.
void expectStlError(const std::string& path, const std::vector<std::string>& fragments) {
    try {
        dem::readStl(path);
        ADD_FAILURE() << "no InputError for " << path;
    } catch (const dem::InputError& error) {
        const std::string message = error.what();
        for (const std::string& fragment : fragments) {
            EXPECT_NE(message.find(fragment), std::string::npos) << "'" << fragment << "' missing in: " << message;
        }
    }
}

}  // namespace

// ================================================================ plane

TEST(PlaneWall, SphereInFrontOverlapsWithPlaneNormal) {
    const dem::PlaneWall plane(Vec3(0, 0, 1), Vec3(0, 0, 2));  // normal normalised
    std::vector<WallContact> contacts;
    plane.findContacts(Vec3(0.3, -0.2, 1.04), 0.05, contacts);
    ASSERT_EQ(contacts.size(), 1u);
    EXPECT_NEAR(contacts[0].overlap, 0.01, 1e-15);
    expectVectorNear(contacts[0].normal, Vec3(0, 0, 1), 1e-15);
    expectVectorNear(contacts[0].point, Vec3(0.3, -0.2, 1.0), 1e-15);
    EXPECT_EQ(contacts[0].feature, 0);

    // Tilted planes, random tangential offsets: overlap = r - signed distance.
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    for (int trial = 0; trial < 200; ++trial) {
        const Vec3 n = randomUnit(rng), p = randomUnit(rng);
        const dem::PlaneWall tilted(p, 3.0 * n);
        const Vec3 tangent = n.cross(randomUnit(rng));
        const double radius = 0.01, distance = radius * uniform(rng);
        std::vector<WallContact> found;
        tilted.findContacts(p + tangent + distance * n, radius, found);
        ASSERT_EQ(found.size(), 1u);
        EXPECT_NEAR(found[0].overlap, radius - distance, 1e-14);
        expectVectorNear(found[0].normal, n, 1e-14);
        expectVectorNear(found[0].point, p + tangent, 1e-14);
    }
}

TEST(PlaneWall, NoContactBehindOrBeyondRadius) {
    const dem::PlaneWall plane(Vec3(0, 0, 0), Vec3(0, 1, 0));
    std::vector<WallContact> contacts;
    plane.findContacts(Vec3(0, -0.01, 0), 0.05, contacts);  // centre behind: one-sided
    plane.findContacts(Vec3(0, 0.05, 0), 0.05, contacts);   // just touching: zero overlap
    plane.findContacts(Vec3(0, 0.2, 0), 0.05, contacts);
    EXPECT_TRUE(contacts.empty());
    EXPECT_THROW(dem::PlaneWall(Vec3(0, 0, 0), Vec3(0, 0, 0)), dem::InputError);
}

// ================================================================ cylinder

TEST(CylinderWall, LateralContactMatchesClosedFormInsideAndOutside) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    for (auto side : {dem::CylinderWall::Side::Inside, dem::CylinderWall::Side::Outside}) {
        for (int trial = 0; trial < 1000; ++trial) {
            const Vec3 axis = randomUnit(rng), base = randomUnit(rng);
            const double R = 0.05, zMin = -0.02, zMax = 0.1, radius = 0.004;
            const dem::CylinderWall cylinder(base, 2.0 * axis, R, zMin, zMax, side);
            // Build the sphere from a surface point S and the outward radial unit u.
            const Vec3 e1 = axis.cross(randomUnit(rng)).normalized(), e2 = axis.cross(e1);
            const double angle = 2 * pi * uniform(rng), z = zMin + (zMax - zMin) * uniform(rng);
            const Vec3 u = std::cos(angle) * e1 + std::sin(angle) * e2;
            const Vec3 surface = base + z * axis + R * u;
            const Vec3 towardsParticles = side == dem::CylinderWall::Side::Inside ? Vec3(-u) : u;
            const double distance = radius * uniform(rng);
            std::vector<WallContact> contacts;
            cylinder.findContacts(surface + distance * towardsParticles, radius, contacts);
            ASSERT_EQ(contacts.size(), 1u);
            EXPECT_NEAR(contacts[0].overlap, radius - distance, 1e-13);
            expectVectorNear(contacts[0].normal, towardsParticles, 1e-10);
            expectVectorNear(contacts[0].point, surface, 1e-13);
            EXPECT_EQ(contacts[0].feature, dem::CylinderWall::lateralFeature);
            // The same sphere on the other side of the surface is behind it: no contact.
            contacts.clear();
            cylinder.findContacts(surface - distance * towardsParticles, radius, contacts);
            EXPECT_TRUE(contacts.empty());
        }
    }
}

// findContacts rejects far spheres from squared distances before its root;
// near every threshold (the surface, the particle radius off it, the rims)
// it must still find exactly the contacts of the plain distance test.
TEST(CylinderWall, EarlyRejectionKeepsEveryContactNearTheThresholds) {
    std::mt19937_64 rng(23);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    const double R = 0.05, zMin = -0.02, zMax = 0.1, radius = 0.0025;
    long found[2] = {0, 0}, rimFound = 0, tested = 0;
    for (auto side : {dem::CylinderWall::Side::Inside, dem::CylinderWall::Side::Outside}) {
        const bool inside = side == dem::CylinderWall::Side::Inside;
        const dem::CylinderWall cylinder(Vec3(0.01, -0.02, 0.03), Vec3(0, 0, 1), R, zMin, zMax, side);
        for (int trial = 0; trial < 200000; ++trial) {
            // Radial and axial offsets at, or within a relative 1e-9 of, the
            // thresholds R, R -+ radius, zMin/zMax (-+ radius), or anywhere.
            auto nearOneOf = [&](std::initializer_list<double> values, double lo, double hi) {
                const int pick = static_cast<int>(uniform(rng) * (values.size() + 1));
                if (pick == static_cast<int>(values.size())) return lo + (hi - lo) * uniform(rng);
                const double v = *(values.begin() + pick);
                return v * (1.0 + 1e-9 * (2.0 * uniform(rng) - 1.0) * (uniform(rng) < 0.5 ? 1.0 : 1e-4));
            };
            const double rho = nearOneOf({R, R - radius, R + radius}, 0.0, R + 2 * radius);
            const double z = nearOneOf({zMin, zMax, zMin - radius, zMax + radius}, zMin - 2 * radius,
                                       zMax + 2 * radius);
            const double angle = 2 * pi * uniform(rng);
            const Vec3 centre = Vec3(0.01, -0.02, 0.03) + Vec3(rho * std::cos(angle), rho * std::sin(angle), z);
            // The plain test, from the computed cylinder coordinates.
            const Vec3 d = centre - Vec3(0.01, -0.02, 0.03);
            const double zc = d.z(), rc = std::sqrt(d.x() * d.x() + d.y() * d.y());
            bool expected;
            if (zc >= zMin && zc <= zMax) {
                const double gap = inside ? R - rc : rc - R;
                expected = gap >= 0.0 && gap < radius;
            } else {
                const double zRim = zc < zMin ? zMin : zMax;
                expected = std::hypot(zc - zRim, rc - R) < radius;
            }
            std::vector<WallContact> contacts;
            cylinder.findContacts(centre, radius, contacts);
            ++tested;
            // Exactly at a threshold the two roundings may differ; 1e-9 off it they may not.
            const double margin = 1e-13;
            const bool borderline = std::abs(std::abs(rc - R) - radius) < margin || std::abs(rc - R) < margin ||
                                    std::abs(std::hypot(zc - (zc < zMin ? zMin : zMax), rc - R) - radius) < margin;
            if (borderline) continue;
            ASSERT_EQ(contacts.size(), expected ? 1u : 0u)
                << (inside ? "inside" : "outside") << ": rho " << rc << ", z " << zc;
            if (expected) {
                ++found[inside];
                rimFound += contacts[0].feature != dem::CylinderWall::lateralFeature;
            }
        }
    }
    // Not vacuous: many contacts on both sides and at the rims.
    EXPECT_GT(found[0], 10000);
    EXPECT_GT(found[1], 10000);
    EXPECT_GT(rimFound, 1000);
    EXPECT_EQ(tested, 400000);
}

TEST(CylinderWall, RimContactBeyondAxialRange) {
    // Die wall: axis z, R = 0.05, z in [0, 0.1].
    const dem::CylinderWall die(Vec3(0, 0, 0), Vec3(0, 0, 1), 0.05, 0.0, 0.1, dem::CylinderWall::Side::Inside);
    std::vector<WallContact> contacts;
    // 3 mm above the top rim and 2 mm inside: distance sqrt(13) mm.
    const Vec3 above(0.048 / std::sqrt(2.0), 0.048 / std::sqrt(2.0), 0.103);
    die.findContacts(above, 0.005, contacts);
    ASSERT_EQ(contacts.size(), 1u);
    const Vec3 rim(0.05 / std::sqrt(2.0), 0.05 / std::sqrt(2.0), 0.1);
    EXPECT_NEAR(contacts[0].overlap, 0.005 - std::sqrt(13.0) * 1e-3, 1e-15);
    expectVectorNear(contacts[0].point, rim, 1e-15);
    expectVectorNear(contacts[0].normal, (above - rim) / (std::sqrt(13.0) * 1e-3), 1e-12);
    EXPECT_EQ(contacts[0].feature, dem::CylinderWall::upperRimFeature);
    // Below the lower rim, from outside the tube: the rim is an edge, touched from any side.
    contacts.clear();
    die.findContacts(Vec3(-0.053, 0, -0.004), 0.006, contacts);
    ASSERT_EQ(contacts.size(), 1u);
    EXPECT_NEAR(contacts[0].overlap, 0.001, 1e-15);
    EXPECT_EQ(contacts[0].feature, dem::CylinderWall::lowerRimFeature);
    expectVectorNear(contacts[0].normal, Vec3(-0.6, 0, -0.8), 1e-12);
    // Far away: near the axis, well above, well below, far outside.
    contacts.clear();
    for (const Vec3& far : {Vec3(0, 0, 0.05), Vec3(0.049, 0, 0.2), Vec3(0.03, 0.03, -0.1), Vec3(0.2, 0, 0.05)}) {
        die.findContacts(far, 0.005, contacts);
    }
    EXPECT_TRUE(contacts.empty());
    EXPECT_THROW(dem::CylinderWall(Vec3(0, 0, 0), Vec3(0, 0, 1), 0.05, 0.1, 0.1, dem::CylinderWall::Side::Inside),
                 dem::InputError);
    EXPECT_THROW(dem::CylinderWall(Vec3(0, 0, 0), Vec3(0, 0, 1), -1.0, 0.0, 0.1, dem::CylinderWall::Side::Inside),
                 dem::InputError);
}

TEST(CylinderWall, BoundingBoxIsTightAroundTheRims) {
    std::mt19937_64 rng(3);
    const Vec3 axis = randomUnit(rng);
    const dem::CylinderWall tube(Vec3(0.1, 0.2, 0.3), axis, 0.05, -0.01, 0.1, dem::CylinderWall::Side::Outside);
    const dem::BoundingBox box = tube.boundingBox();
    dem::BoundingBox sampled;
    const Vec3 e1 = axis.cross(randomUnit(rng)).normalized(), e2 = axis.cross(e1);
    for (int k = 0; k < 20000; ++k) {
        const double angle = 2 * pi * k / 20000;
        for (double z : {-0.01, 0.1}) {
            sampled.expand(Vec3(0.1, 0.2, 0.3) + z * axis + 0.05 * (std::cos(angle) * e1 + std::sin(angle) * e2));
        }
    }
    EXPECT_TRUE((sampled.lower.array() >= box.lower.array() - 1e-15).all());
    EXPECT_TRUE((sampled.upper.array() <= box.upper.array() + 1e-15).all());
    expectVectorNear(sampled.lower, box.lower, 1e-8);
    expectVectorNear(sampled.upper, box.upper, 1e-8);
}

// ================================================================ triangle closest point

namespace {

// Independent closest point: projection when inside, else the best of the three clamped segments.
Vec3 bruteClosest(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 n = (b - a).cross(c - a);
    const Vec3 q = p - ((p - a).dot(n) / n.squaredNorm()) * n;
    const double u = (c - b).cross(q - b).dot(n), v = (a - c).cross(q - c).dot(n), w = (b - a).cross(q - a).dot(n);
    if (u >= 0 && v >= 0 && w >= 0) {
        return q;
    }
    Vec3 best = a;
    for (const auto& [s, e] : {std::pair<Vec3, Vec3>{a, b}, {b, c}, {c, a}}) {
        const double t = std::clamp((p - s).dot(e - s) / (e - s).squaredNorm(), 0.0, 1.0);
        const Vec3 candidate = s + t * (e - s);
        if ((candidate - p).norm() < (best - p).norm()) {
            best = candidate;
        }
    }
    return best;
}

}  // namespace

TEST(TriangleClosestPoint, AgreesWithBruteForceInEveryRegion) {
    using Region = dem::TriangleClosestPoint::Region;
    std::mt19937_64 rng(2024);
    std::uniform_real_distribution<double> box(-1.0, 1.0), wide(-1.5, 1.5), unit(0.0, 1.0);
    int regionCount[3] = {0, 0, 0};
    double worstRelative = 0.0;
    for (int query = 0; query < 10000; ++query) {
        const Vec3 a(box(rng), box(rng), box(rng)), b(box(rng), box(rng), box(rng)), c(box(rng), box(rng), box(rng));
        const Vec3 p(wide(rng), wide(rng), wide(rng));
        const dem::TriangleClosestPoint found = dem::closestPointOnTriangle(p, a, b, c);
        const Vec3 expected = bruteClosest(p, a, b, c);
        const double scale = std::max((expected - p).norm(), 1e-3);
        worstRelative = std::max(worstRelative, (found.point - expected).norm() / scale);
        ++regionCount[int(found.region)];
        // The reported region must describe where the point is.
        const Vec3 corners[3] = {a, b, c};
        if (found.region == Region::Vertex) {
            EXPECT_EQ(found.point, corners[found.index]);
        } else if (found.region == Region::Edge) {
            const Vec3 s = corners[found.index], e = corners[(found.index + 1) % 3];
            EXPECT_NEAR((found.point - s).cross(e - s).norm(), 0.0, 1e-12);
        } else {
            const Vec3 n = (b - a).cross(c - a).normalized();
            EXPECT_NEAR(std::abs((p - found.point).normalized().dot(n)), 1.0, 1e-9);
        }
        // Sampling: no point of the triangle is closer than the answer.
        if (query % 50 == 0) {
            for (int s = 0; s < 2000; ++s) {
                double u = unit(rng), v = unit(rng);
                if (u + v > 1) {
                    u = 1 - u;
                    v = 1 - v;
                }
                const Vec3 sample = a + u * (b - a) + v * (c - a);
                ASSERT_GE((sample - p).norm(), (found.point - p).norm() - 1e-12);
            }
        }
    }
    EXPECT_LT(worstRelative, 1e-9);
    // The random queries exercise all three kinds of region.
    EXPECT_GT(regionCount[int(Region::Face)], 500);
    EXPECT_GT(regionCount[int(Region::Edge)], 500);
    EXPECT_GT(regionCount[int(Region::Vertex)], 500);
}

// ================================================================ mesh contacts

TEST(TriangleMesh, FlatSquareGivesOneContactOverFaceDiagonalAndVertex) {
    const dem::TriangleMesh square(squareTriangles(1.0, 1));  // diagonal (0,0)-(1,1)
    ASSERT_EQ(square.triangleCount(), 2u);
    ASSERT_EQ(square.vertexCount(), 4u);
    const double radius = 0.1, height = 0.07;
    for (const Vec3& over : {Vec3(0.7, 0.2, 0), Vec3(0.4, 0.4, 0), Vec3(0.5 + 1e-13, 0.5, 0), Vec3(0, 0, 0),
                             Vec3(1, 1, 0), Vec3(1, 0, 0), Vec3(0.5, 1, 0)}) {
        const auto contacts = contactsOf(square, over + Vec3(0, 0, height), radius);
        ASSERT_EQ(contacts.size(), 1u) << "over " << over.transpose();
        EXPECT_NEAR(contacts[0].overlap, radius - height, 1e-15);
        expectVectorNear(contacts[0].normal, Vec3(0, 0, 1), 1e-14);
        expectVectorNear(contacts[0].point, over, 1e-15);
    }
    // Beyond the shared corner (1, 1): a vertex contact along the oblique direction.
    const Vec3 centre(1.03, 1.03, 0.07);
    const auto corner = contactsOf(square, centre, radius);
    ASSERT_EQ(corner.size(), 1u);
    const Vec3 offset = centre - Vec3(1, 1, 0);
    EXPECT_NEAR(corner[0].overlap, radius - offset.norm(), 1e-15);
    expectVectorNear(corner[0].normal, offset.normalized(), 1e-15);
    EXPECT_EQ(corner[0].feature, square.vertexFeature(2));
    // From below (two-sided mesh), over the diagonal.
    const auto below = contactsOf(square, Vec3(0.3, 0.3, -0.05), radius);
    ASSERT_EQ(below.size(), 1u);
    expectVectorNear(below[0].normal, Vec3(0, 0, -1), 1e-15);
}

TEST(TriangleMesh, FeatureIdIsStableWhileSlidingAcrossCoplanarTriangles) {
    // Fan of four triangles around a centre vertex, and a 20000-triangle plate.
    const Vec3 m(0.5, 0.5, 0), a(0, 0, 0), b(1, 0, 0), c(1, 1, 0), d(0, 1, 0);
    const dem::TriangleMesh fan({{a, b, m}, {b, c, m}, {c, d, m}, {d, a, m}});
    const dem::TriangleMesh plate(squareTriangles(1.0, 100));
    for (const dem::TriangleMesh* mesh : {&fan, &plate}) {
        const int feature = contactsOf(*mesh, Vec3(0.2, 0.8, 0.004), 0.005).at(0).feature;
        for (int step = 0; step <= 1000; ++step) {
            // Path through the fan's centre vertex and across many plate diagonals.
            const double s = step / 1000.0;
            const Vec3 centre(0.2 + 0.6 * s, 0.8 - 0.6 * s, 0.004);
            const auto contacts = contactsOf(*mesh, centre, 0.005);
            ASSERT_EQ(contacts.size(), 1u) << "step " << step;
            EXPECT_EQ(contacts[0].feature, feature);
            EXPECT_NEAR(contacts[0].overlap, 0.001, 1e-15);
        }
    }
}

TEST(TriangleMesh, CubeEdgeAndVertexFromOutsideGiveOneContact) {
    const dem::TriangleMesh cube(boxTriangles(Vec3(0, 0, 0), Vec3(1, 1, 1)));
    ASSERT_EQ(cube.vertexCount(), 8u);
    const double radius = 0.08, gap = 0.05;
    // Edge x = 1, z = 1 along y, including the points where face diagonals end.
    for (double y : {0.0, 0.3, 0.5, 0.999, 1.0}) {
        const Vec3 onEdge(1, y, 1), outward = Vec3(1, 0, 1).normalized();
        const auto contacts = contactsOf(cube, onEdge + gap * outward, radius);
        ASSERT_EQ(contacts.size(), 1u) << "y = " << y;
        EXPECT_NEAR(contacts[0].overlap, radius - gap, 1e-14);
        expectVectorNear(contacts[0].normal, outward, 1e-14);
        expectVectorNear(contacts[0].point, onEdge, 1e-14);
    }
    const Vec3 diagonal = Vec3(1, 1, 1).normalized();
    const auto vertex = contactsOf(cube, Vec3(1, 1, 1) + gap * diagonal, radius);
    ASSERT_EQ(vertex.size(), 1u);
    expectVectorNear(vertex[0].normal, diagonal, 1e-14);
    EXPECT_NEAR(vertex[0].overlap, radius - gap, 1e-14);
    // Over the top face near the edge: the side face's edge point (0.058 away) is not a contact.
    const auto face = contactsOf(cube, Vec3(0.97, 0.5, 1.05), radius);
    ASSERT_EQ(face.size(), 1u);
    expectVectorNear(face[0].normal, Vec3(0, 0, 1), 1e-15);
    EXPECT_NEAR(face[0].overlap, 0.03, 1e-15);
}

TEST(TriangleMesh, ConcaveCornerKeepsOneContactPerFace) {
    // A sphere in an inner corner of a box (the die bottom meets two walls).
    const dem::TriangleMesh box(boxTriangles(Vec3(0, 0, 0), Vec3(1, 1, 1)));
    const auto contacts = contactsOf(box, Vec3(0.05, 0.06, 0.07), 0.08);
    ASSERT_EQ(contacts.size(), 3u);
    Vec3 normalSum = Vec3::Zero();
    double overlapSum = 0.0;
    for (const auto& contact : contacts) {
        normalSum += contact.normal;
        overlapSum += contact.overlap;
    }
    expectVectorNear(normalSum, Vec3(1, 1, 1), 1e-14);
    EXPECT_NEAR(overlapSum, 0.03 + 0.02 + 0.01, 1e-14);
}

TEST(TriangleMesh, GridQueryFindsTheNearestSurfacePointAtConstantCost) {
    // UV sphere with ~4900 triangles; compare the deepest contact with all triangles.
    const dem::TriangleMesh ball(uvSphereTriangles(50, 50));
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    std::size_t maxCandidates = 0, totalCandidates = 0;
    for (int query = 0; query < 2000; ++query) {
        const double radius = 0.03;
        const Vec3 centre = (1.0 + 0.03 * uniform(rng)) * randomUnit(rng);
        double nearest = 1e300;
        for (std::size_t t = 0; t < ball.triangleCount(); ++t) {
            const Triangle tri = ball.triangle(t);
            nearest = std::min(nearest, (dem::closestPointOnTriangle(centre, tri[0], tri[1], tri[2]).point - centre).norm());
        }
        const auto contacts = contactsOf(ball, centre, radius);
        double deepest = 0.0;
        for (const auto& contact : contacts) {
            deepest = std::max(deepest, contact.overlap);
        }
        if (nearest < radius) {
            ASSERT_FALSE(contacts.empty());
            EXPECT_NEAR(deepest, radius - nearest, 1e-14);
        } else {
            EXPECT_TRUE(contacts.empty());
        }
        const std::size_t candidates = ball.candidateCount(centre, radius);
        maxCandidates = std::max(maxCandidates, candidates);
        totalCandidates += candidates;
    }
    // The 100 slivers meeting at the poles share a cell: the worst query tests
    // about 160 triangles, a typical one about 30, of 4900.
    std::printf("UV sphere: %zu triangles, candidates per query: mean %.1f, max %zu\n", ball.triangleCount(),
                double(totalCandidates) / 2000, maxCandidates);
    EXPECT_LT(maxCandidates, 250u);
    EXPECT_LT(double(totalCandidates) / 2000, 60.0);
    // The 20000-triangle plate: a particle-sized query tests a handful of triangles.
    const dem::TriangleMesh plate(squareTriangles(1.0, 100));
    EXPECT_LT(plate.candidateCount(Vec3(0.5, 0.5, 0.002), 0.005), 40u);
}

TEST(TriangleMesh, EarlyRejectionKeepsEveryTouchedFace) {
    // findContacts skips a candidate whose plane or box the sphere does not
    // reach before the closest-point search.  Spheres at a relative 1e-9, 1e-6
    // or 1e-3 of the contact distance from a face, on either side, near its
    // edges or inside it: every face that the brute-force closest point shows
    // touched (region Face, distance < radius) must be among the contacts.
    const dem::TriangleMesh ball(uvSphereTriangles(12, 12));
    const dem::TriangleMesh plate(squareTriangles(1.0, 10));
    std::mt19937_64 rng(31);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    long faces = 0, backSide = 0;
    for (const dem::TriangleMesh* mesh : {&ball, &plate}) {
        for (int trial = 0; trial < 40000; ++trial) {
            const std::size_t t = std::min(mesh->triangleCount() - 1, std::size_t(uniform(rng) * mesh->triangleCount()));
            const Triangle tri = mesh->triangle(t);
            // A point inside the triangle, half the time within 1e-6 of an edge.
            double u = uniform(rng), v = uniform(rng);
            if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
            if (uniform(rng) < 0.5) v = 1e-6 * uniform(rng);
            const Vec3 onFace = tri[0] + u * (tri[1] - tri[0]) + v * (tri[2] - tri[0]);
            const double radius = 0.01 + 0.04 * uniform(rng);
            const double scale = std::pow(10.0, -3.0 * (1 + int(uniform(rng) * 3)));
            const double side = uniform(rng) < 0.5 ? 1.0 : -1.0;
            const Vec3 centre = onFace + side * radius * (1.0 + scale * (2.0 * uniform(rng) - 1.0)) * mesh->faceNormal(t);
            const auto contacts = contactsOf(*mesh, centre, radius);
            for (std::size_t k = 0; k < mesh->triangleCount(); ++k) {
                const Triangle other = mesh->triangle(k);
                const auto closest = dem::closestPointOnTriangle(centre, other[0], other[1], other[2]);
                const double distance = (closest.point - centre).norm();
                if (closest.region != dem::TriangleClosestPoint::Region::Face || distance >= radius ||
                    radius - distance < 1e-13)
                    continue;
                bool reported = false;
                for (const auto& contact : contacts) reported |= contact.feature == mesh->faceFeature(k);
                ASSERT_TRUE(reported) << "triangle " << k << " at " << distance << " of radius " << radius;
                ++faces;
                backSide += mesh->faceNormal(k).dot(centre - closest.point) < 0.0;
            }
        }
    }
    // Not vacuous: many touched faces, from both sides.
    EXPECT_GT(faces, 30000);
    EXPECT_GT(backSide, 10000);
}

TEST(TriangleMesh, ListedTrianglesGiveTheContactsOfTheWholeMesh) {
    // The step searches a mesh wall only over the triangles listed within
    // radius + skin of the particle at the list build; it moves less than
    // skin/2 before the next one.  Its contacts must be those of the whole
    // mesh, bit for bit, in whatever order the list holds the triangles.
    const dem::TriangleMesh ball(uvSphereTriangles(12, 12));
    const dem::TriangleMesh plate(squareTriangles(1.0, 10));
    std::mt19937_64 rng(37);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    long contacts = 0, edgesAndVertices = 0;
    for (const dem::TriangleMesh* mesh : {&ball, &plate}) {
        for (int trial = 0; trial < 20000; ++trial) {
            const double radius = 0.02 + 0.06 * uniform(rng), skin = 0.5 * radius;
            // Near the surface: a vertex or a point of a triangle, pushed off it.
            const std::size_t t = std::min(mesh->triangleCount() - 1, std::size_t(uniform(rng) * mesh->triangleCount()));
            const Triangle tri = mesh->triangle(t);
            const double u = uniform(rng), v = (1.0 - u) * uniform(rng);
            const Vec3 onSurface = tri[0] + u * (tri[1] - tri[0]) + v * (tri[2] - tri[0]);
            const Vec3 listedAt = onSurface + (radius + 0.5 * skin) * uniform(rng) * randomUnit(rng);
            std::vector<int> listed;
            mesh->nearTriangles(listedAt, radius + skin, listed);
            ASSERT_TRUE(std::is_sorted(listed.begin(), listed.end()));
            // Moved by up to skin/2 (just under): half the time straight at the
            // surface point it was pushed from, else in any direction.
            const Vec3 towards = (onSurface - listedAt).normalized();
            const Vec3 centre = uniform(rng) < 0.5 && (onSurface - listedAt).norm() > 0.5 * skin
                                    ? Vec3(listedAt + 0.4999 * skin * towards)
                                    : Vec3(listedAt + 0.4999 * skin * std::cbrt(uniform(rng)) * randomUnit(rng));
            const auto whole = contactsOf(*mesh, centre, radius);
            for (int order = 0; order < 2; ++order) {
                if (order == 1) std::reverse(listed.begin(), listed.end());
                std::vector<WallContact> among;
                mesh->findContactsAmong(centre, radius, listed.data(), int(listed.size()), among);
                ASSERT_EQ(among.size(), whole.size()) << "trial " << trial;
                for (std::size_t k = 0; k < whole.size(); ++k) {
                    EXPECT_EQ(among[k].feature, whole[k].feature);
                    EXPECT_EQ(among[k].overlap, whole[k].overlap);
                    EXPECT_EQ(among[k].point, whole[k].point);
                    EXPECT_EQ(among[k].normal, whole[k].normal);
                }
            }
            contacts += long(whole.size());
            for (const auto& c : whole) edgesAndVertices += c.feature % 4 != 0 || c.feature >= 4 * int(mesh->triangleCount());
        }
    }
    // Not vacuous: many contacts, edge and vertex ones among them.
    EXPECT_GT(contacts, 20000);
    EXPECT_GT(edgesAndVertices, 1000);
}

// ================================================================ STL

TEST(Stl, AsciiAndBinaryGiveIdenticalTriangles) {
    TempDir dir;
    // Coordinates that are not exact in binary: the float32 rounding is the same in both files.
    const auto triangles = boxTriangles(Vec3(0.1, -0.2, 0.3), Vec3(0.7, 0.15, 1.1));
    writeAsciiStl(dir.file("part.stl"), triangles);
    writeBinaryStl(dir.file("part_bin.stl"), triangles, "solid header that lies: this file is binary");
    const auto ascii = dem::readStl(dir.file("part.stl"));
    const auto binary = dem::readStl(dir.file("part_bin.stl"));
    ASSERT_EQ(ascii.size(), 12u);
    ASSERT_EQ(binary.size(), 12u);
    for (std::size_t t = 0; t < 12; ++t) {
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(ascii[t][c], binary[t][c]);
            expectVectorNear(binary[t][c], triangles[t][c], 1e-7);
        }
    }
    // Scale factor (mm -> m).
    const auto scaled = dem::readStl(dir.file("part_bin.stl"), 1e-3);
    EXPECT_EQ(scaled[5][2], binary[5][2] * 1e-3);
    // The mesh from the file is the closed box: 8 welded vertices.
    const auto mesh = dem::TriangleMesh::fromStl(dir.file("part.stl"));
    EXPECT_EQ(mesh.vertexCount(), 8u);
    EXPECT_TRUE(mesh.containsPoint(Vec3(0.4, 0.0, 0.7)));
    EXPECT_FALSE(mesh.containsPoint(Vec3(0.4, 0.2, 0.7)));
}

TEST(Stl, MissingOrCorruptFilesNameTheFileAndTheProblem) {
    TempDir dir;
    expectStlError(dir.file("absent.stl"), {"absent.stl", "cannot be opened"});

    writeText(dir.file("badnumber.stl"),
              "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 abc 0\n"
              "   vertex 0 1 0\n  endloop\n endfacet\nendsolid x\n");
    expectStlError(dir.file("badnumber.stl"), {"badnumber.stl", "line 5", "'abc'"});

    writeText(dir.file("cut.stl"), "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n");
    expectStlError(dir.file("cut.stl"), {"cut.stl", "unexpected end of file"});

    writeText(dir.file("quad.stl"),
              "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n"
              "   vertex 1 1 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid x\n");
    expectStlError(dir.file("quad.stl"), {"quad.stl", "more than 3 vertices"});

    writeText(dir.file("empty.stl"), "solid nothing\nendsolid nothing\n");
    expectStlError(dir.file("empty.stl"), {"empty.stl", "no triangles"});

    writeBinaryStl(dir.file("truncated.stl"), squareTriangles(1.0, 2), "binary part");
    std::filesystem::resize_file(dir.file("truncated.stl"), 84 + 50 * 8 - 7);
    expectStlError(dir.file("truncated.stl"), {"truncated.stl", "84 + 50 * 8 = 484", "477"});

    writeText(dir.file("tiny.stl"), "garbage");
    expectStlError(dir.file("tiny.stl"), {"tiny.stl", "7 bytes"});

    EXPECT_THROW(dem::readStl(dir.file("badnumber.stl"), 0.0), dem::InputError);
}

// ================================================================ containsPoint

TEST(TriangleMesh, ContainsPointMatchesAnalyticSolids) {
    std::mt19937_64 rng(99);
    std::uniform_real_distribution<double> uniform(-0.5, 1.5);
    const dem::TriangleMesh cube(boxTriangles(Vec3(0, 0, 0), Vec3(1, 1, 1)));
    int wrong = 0;
    for (int k = 0; k < 10000; ++k) {
        // Every fifth point sits on a lattice whose rays would graze face diagonals.
        Vec3 p(uniform(rng), uniform(rng), uniform(rng));
        if (k % 5 == 0) {
            p = Vec3(0.25 * (k % 7) - 0.25, 0.25 * ((k / 7) % 7) - 0.25, 0.5);
        }
        const bool inside = (p.array() > 0.0).all() && (p.array() < 1.0).all();
        const bool onBoundary = ((p.array().abs() < 1e-12) || ((p.array() - 1.0).abs() < 1e-12)).any();
        if (!onBoundary && cube.containsPoint(p) != inside) {
            ++wrong;
        }
    }
    EXPECT_EQ(wrong, 0);

    // Points whose ray runs exactly through a face diagonal, a cube edge or a
    // vertex (a single ray would count 0 or 2 crossings there).
    int aimed = 0;
    for (const Vec3& target : {Vec3(0.5, 0.5, 1), Vec3(0.25, 0.25, 0), Vec3(1, 0.5, 0.5), Vec3(0, 0.7, 0.7),
                               Vec3(1, 0.4, 1), Vec3(0.5, 1, 0), Vec3(1, 1, 1), Vec3(0, 0, 0), Vec3(1, 0, 1)}) {
        for (const Vec3& ray : dem::TriangleMesh::parityRays()) {
            for (double s : {-0.6, -0.3, -0.05, 0.05, 0.3}) {
                const Vec3 p = target - s * ray;  // the ray from p passes through target when s > 0
                const bool inside = (p.array() > 0.0).all() && (p.array() < 1.0).all();
                EXPECT_EQ(cube.containsPoint(p), inside) << p.transpose();
                ++aimed;
            }
        }
    }
    EXPECT_EQ(aimed, 135);

    // Closed 24-sided prism (the repose-angle cylinder, 43 mm diameter): analytic polygon test.
    const int sides = 24;
    const double R = 0.0215, height = 0.05;
    const dem::TriangleMesh prism(prismTriangles(R, height, sides));
    std::uniform_real_distribution<double> across(-0.03, 0.03), along(-0.01, 0.06);
    wrong = 0;
    for (int k = 0; k < 10000; ++k) {
        const Vec3 p(across(rng), across(rng), along(rng));
        bool inside = p.z() > 0 && p.z() < height;
        for (int s = 0; s < sides && inside; ++s) {
            const double mid = 2 * pi * (s + 0.5) / sides;  // outward normal of side s
            inside = p.x() * std::cos(mid) + p.y() * std::sin(mid) < R * std::cos(pi / sides);
        }
        if (prism.containsPoint(p) != inside) {
            ++wrong;
        }
    }
    EXPECT_EQ(wrong, 0);
}

// A closed box whose faces are each split into cells x cells squares: many
// small triangles, so the triangle grid has many cells for a ray to walk.
std::vector<Triangle> fineBoxTriangles(const Vec3& lo, const Vec3& hi, int cells) {
    std::vector<Triangle> triangles;
    for (const Triangle& coarse : boxTriangles(lo, hi)) {
        // Map each coarse triangle's parameter square onto cells x cells
        // sub-triangles: the pair of coarse triangles of a face is split alike.
        const Vec3& a = coarse[0];
        const Vec3 u = coarse[1] - a, v = coarse[2] - coarse[1];
        for (int i = 0; i < cells; ++i) {
            for (int j = 0; j <= i; ++j) {
                auto at = [&](double s, double t) { return Vec3(a + (s / cells) * u + (t / cells) * v); };
                triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
                if (j < i) triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
            }
        }
    }
    return triangles;
}

// UV sphere of radius r about the origin (closed; poles as triangle fans).
std::vector<Triangle> sphereTriangles(double r, int rings, int segments) {
    auto point = [&](int ring, int segment) {
        const double polar = pi * ring / rings, azimuth = 2 * pi * segment / segments;
        return Vec3(r * std::sin(polar) * std::cos(azimuth), r * std::sin(polar) * std::sin(azimuth), r * std::cos(polar));
    };
    std::vector<Triangle> triangles;
    for (int ring = 0; ring < rings; ++ring) {
        for (int segment = 0; segment < segments; ++segment) {
            const Vec3 a = point(ring, segment), b = point(ring + 1, segment), c = point(ring + 1, segment + 1),
                       d = point(ring, segment + 1);
            if (ring > 0) triangles.push_back({a, b, d});
            if (ring + 1 < rings) triangles.push_back({b, c, d});
        }
    }
    return triangles;
}

TEST(TriangleMesh, ClosedMeshesAreTold) {
    EXPECT_TRUE(dem::TriangleMesh(boxTriangles(Vec3(0, 0, 0), Vec3(1, 2, 3))).isClosed());
    EXPECT_TRUE(dem::TriangleMesh(prismTriangles(0.0215, 0.05, 24)).isClosed());
    EXPECT_TRUE(dem::TriangleMesh(sphereTriangles(1.0, 16, 24)).isClosed());
    EXPECT_TRUE(dem::TriangleMesh(fineBoxTriangles(Vec3(0, 0, 0), Vec3(1, 1, 1), 5)).isClosed());
    // A flat plate, and a box with one triangle missing, have open borders.
    EXPECT_FALSE(dem::TriangleMesh(squareTriangles(1.0, 4)).isClosed());
    auto open = boxTriangles(Vec3(0, 0, 0), Vec3(1, 1, 1));
    open.pop_back();
    EXPECT_FALSE(dem::TriangleMesh(open).isClosed());
}

TEST(TriangleMesh, ContainsPointOnFineMeshesMatchesTheSolid) {
    // Thousands of triangles in a grid of many cells: the rays walk the grid,
    // and a triangle listed in several cells along a ray counts once.
    std::mt19937_64 rng(7);
    const dem::TriangleMesh box(fineBoxTriangles(Vec3(-0.3, 0.1, 0.2), Vec3(0.5, 0.4, 1.0), 24));
    ASSERT_EQ(box.triangleCount(), 6u * 2 * 24 * 24);
    std::uniform_real_distribution<double> x(-0.5, 0.7), y(-0.1, 0.6), z(0.0, 1.2);
    int wrong = 0, inside = 0;
    for (int k = 0; k < 20000; ++k) {
        const Vec3 p(x(rng), y(rng), z(rng));
        const bool expected = p.x() > -0.3 && p.x() < 0.5 && p.y() > 0.1 && p.y() < 0.4 && p.z() > 0.2 && p.z() < 1.0;
        inside += expected;
        if (box.containsPoint(p) != expected) ++wrong;
    }
    EXPECT_EQ(wrong, 0);
    EXPECT_GT(inside, 2000);  // both answers are exercised

    // A sphere of 64 x 32 facets: points clear of the faceted shell by 1 %.
    const double r = 0.02;
    const dem::TriangleMesh sphere(sphereTriangles(r, 32, 64));
    std::uniform_real_distribution<double> across(-1.3 * r, 1.3 * r);
    wrong = 0;
    int tested = 0;
    for (int k = 0; k < 20000; ++k) {
        const Vec3 p(across(rng), across(rng), across(rng));
        if (std::abs(p.norm() - r) < 0.01 * r) continue;
        ++tested;
        if (sphere.containsPoint(p) != (p.norm() < r)) ++wrong;
    }
    EXPECT_EQ(wrong, 0);
    EXPECT_GT(tested, 19000);
}

TEST(Wall, EnclosesPointBehindPlanesAndInsideClosedPartsOnly) {
    const dem::Wall floor{"floor", dem::PlaneWall(Vec3(0, 0, 0.1), Vec3(0, 0, 1)), dem::WallMotion(), 0};
    EXPECT_TRUE(floor.enclosesPoint(Vec3(3, -2, 0.099), 0.0));
    EXPECT_FALSE(floor.enclosesPoint(Vec3(3, -2, 0.101), 0.0));
    // A tube is a shell: both sides are free space.
    const dem::Wall tube{"tube", dem::CylinderWall(Vec3(0, 0, 0), Vec3(0, 0, 1), 0.02, 0.0, 0.05,
                                                   dem::CylinderWall::Side::Inside),
                         dem::WallMotion(), 0};
    EXPECT_FALSE(tube.enclosesPoint(Vec3(0.03, 0, 0.02), 0.0));
    EXPECT_FALSE(tube.enclosesPoint(Vec3(0.01, 0, 0.02), 0.0));
    // A closed part, moved: the test follows its pose at the time asked.
    dem::Wall block{"block", dem::MeshWall(std::make_shared<const dem::TriangleMesh>(
                                 boxTriangles(Vec3(0, 0, 0), Vec3(0.01, 0.01, 0.002)))),
                    dem::WallMotion(), 1};
    block.motion.addTranslation(1.0, 2.0, Vec3(0.1, 0, 0));
    EXPECT_TRUE(block.enclosesPoint(Vec3(0.005, 0.005, 0.001), 0.5));
    EXPECT_FALSE(block.enclosesPoint(Vec3(0.005, 0.005, 0.003), 0.5));
    EXPECT_FALSE(block.enclosesPoint(Vec3(0.005, 0.005, 0.001), 3.0));  // it has moved 0.1 m on
    EXPECT_TRUE(block.enclosesPoint(Vec3(0.105, 0.005, 0.001), 3.0));
    block.motion.setRemovalTime(4.0);
    EXPECT_FALSE(block.enclosesPoint(Vec3(0.105, 0.005, 0.001), 4.0));  // removed
    // An open surface (a thin sheet) has no inside.
    const dem::Wall sheet{"sheet", dem::MeshWall(std::make_shared<const dem::TriangleMesh>(squareTriangles(1.0, 2))),
                          dem::WallMotion(), 1};
    EXPECT_FALSE(sheet.enclosesPoint(Vec3(0.5, 0.5, -1e-3), 0.0));
}

// ================================================================ motion

TEST(WallMotion, TranslationStartsAndStopsOnTime) {
    dem::WallMotion shoe;
    const Vec3 v(0.0405, 0, 0);
    shoe.addTranslation(2.0, 4.0, v);
    EXPECT_EQ(shoe.at(1.0).translation, Vec3::Zero());
    EXPECT_EQ(shoe.at(2.0).translation, Vec3::Zero());
    EXPECT_NEAR((shoe.at(3.0).translation - Vec3(0.0405, 0, 0)).norm(), 0.0, 1e-17);
    EXPECT_NEAR((shoe.at(4.0).translation - Vec3(0.081, 0, 0)).norm(), 0.0, 1e-17);
    EXPECT_NEAR((shoe.at(50.0).translation - Vec3(0.081, 0, 0)).norm(), 0.0, 1e-17);
    EXPECT_EQ(shoe.at(50.0).rotation, dem::Mat3::Identity());
    const Vec3 anywhere(0.3, -1, 2);
    EXPECT_EQ(shoe.velocityAt(anywhere, 1.0), Vec3::Zero());
    EXPECT_EQ(shoe.velocityAt(anywhere, 2.0), v);
    EXPECT_EQ(shoe.velocityAt(anywhere, 3.999), v);
    EXPECT_EQ(shoe.velocityAt(anywhere, 4.0), Vec3::Zero());
    // Stateless closed form: a "restart" at t = 3.3 sees exactly the same pose.
    const Vec3 fresh = dem::WallMotion(shoe).at(3.3).translation;
    shoe.at(10.0);
    EXPECT_EQ(shoe.at(3.3).translation, fresh);
}

TEST(WallMotion, RotationTiltsAPlateByTheExpectedAngle) {
    dem::WallMotion tilt;  // hinge along +y through (0, 0, 0.1), 0.01 rad/s for 50 s
    const Vec3 hinge(0, 0, 0.1);
    tilt.addRotation(10.0, 60.0, hinge, Vec3(0, 3, 0), 0.01);
    const Vec3 tip(1, 0, 0.1);  // reference point on the plate
    for (const auto& [time, angle] : {std::pair<double, double>{5.0, 0.0}, {35.0, 0.25}, {60.0, 0.5}, {100.0, 0.5}}) {
        // Right-hand rotation about +y takes +x towards -z.
        expectVectorNear(tilt.at(time).apply(tip), Vec3(std::cos(angle), 0, 0.1 - std::sin(angle)), 1e-15);
    }
    // Velocity field omega x (p - hinge), and it equals the time derivative of the pose.
    const Vec3 p = tilt.at(35.0).apply(tip);
    const Vec3 expected = Vec3(0, 0.01, 0).cross(p - hinge);
    expectVectorNear(tilt.velocityAt(p, 35.0), expected, 1e-17);
    expectVectorNear(expected, Vec3(-0.01 * std::sin(0.25), 0, -0.01 * std::cos(0.25)), 1e-17);
    const double h = 1e-3;
    const Vec3 derivative = (tilt.at(35.0 + h).apply(tip) - tilt.at(35.0 - h).apply(tip)) / (2 * h);
    expectVectorNear(derivative, expected, 1e-9);
    EXPECT_EQ(tilt.velocityAt(p, 60.0), Vec3::Zero());
}

TEST(WallMotion, SegmentsComposeInOrderAndRemovalEndsTheWall) {
    dem::WallMotion motion;
    motion.addTranslation(0.0, 1.0, Vec3(0, 0, -0.02));              // lower by 2 cm
    motion.addRotation(2.0, 3.0, Vec3(0, 0, 0), Vec3(0, 0, 1), pi / 2);  // quarter turn about z
    motion.addTranslation(3.0, 5.0, Vec3(0.01, 0, 0));
    motion.setRemovalTime(6.0);
    const Vec3 x(1, 0, 0);
    expectVectorNear(motion.at(1.5).apply(x), Vec3(1, 0, -0.02), 1e-16);
    expectVectorNear(motion.at(3.0).apply(x), Vec3(0, 1, -0.02), 1e-15);
    expectVectorNear(motion.at(5.5).apply(x), Vec3(0.02, 1, -0.02), 1e-15);
    // Continuity at segment ends.
    expectVectorNear(motion.at(3.0 - 1e-12).apply(x), motion.at(3.0).apply(x), 1e-11);
    EXPECT_TRUE(motion.isActive(5.999));
    EXPECT_FALSE(motion.isActive(6.0));

    EXPECT_THROW(motion.addTranslation(4.0, 7.0, Vec3(1, 0, 0)), dem::InputError);  // overlaps
    dem::WallMotion invalid;
    EXPECT_THROW(invalid.addTranslation(2.0, 2.0, Vec3(1, 0, 0)), dem::InputError);
    EXPECT_THROW(invalid.addRotation(0.0, 1.0, Vec3(0, 0, 0), Vec3(0, 0, 0), 1.0), dem::InputError);
    EXPECT_THROW(invalid.addTranslation(0.0, NAN, Vec3(1, 0, 0)), dem::InputError);
}

// ================================================================ moving walls

TEST(Wall, TranslatingMeshReportsWorldPointAndWallVelocity) {
    dem::Wall plate{"shoe bottom", dem::MeshWall(std::make_shared<const dem::TriangleMesh>(squareTriangles(1.0, 4))),
                    dem::WallMotion(), 1};
    plate.motion.addTranslation(0.0, 10.0, Vec3(0.0405, 0, 0));
    std::vector<WallContact> contacts;
    plate.findContacts(Vec3(0.162 + 0.5, 0.5, 0.07), 0.1, 4.0, contacts);
    ASSERT_EQ(contacts.size(), 1u);
    expectVectorNear(contacts[0].point, Vec3(0.662, 0.5, 0), 1e-15);
    expectVectorNear(contacts[0].wallVelocity, Vec3(0.0405, 0, 0), 1e-17);
    EXPECT_NEAR(contacts[0].overlap, 0.03, 1e-15);
    // After the stroke the plate rests: zero velocity, same place.
    contacts.clear();
    plate.findContacts(Vec3(0.405 + 0.99, 0.5, 0.07), 0.1, 12.0, contacts);
    ASSERT_EQ(contacts.size(), 1u);
    EXPECT_EQ(contacts[0].wallVelocity, Vec3::Zero());
    const dem::BoundingBox box = plate.boundingBox(12.0);
    expectVectorNear(box.lower, Vec3(0.405, 0, 0), 1e-15);
    expectVectorNear(box.upper, Vec3(1.405, 1, 0), 1e-15);
    // Removed: no contacts, empty box.
    plate.motion.setRemovalTime(20.0);
    contacts.clear();
    plate.findContacts(Vec3(0.405 + 0.5, 0.5, 0.07), 0.1, 20.0, contacts);
    EXPECT_TRUE(contacts.empty());
    EXPECT_TRUE(plate.boundingBox(20.0).isEmpty());
}

TEST(Wall, RotatingPlateContactInWorldFrame) {
    dem::Wall plate{"inclined plate", dem::MeshWall(std::make_shared<const dem::TriangleMesh>(squareTriangles(1.0, 1))),
                    dem::WallMotion(), 1};
    const double omega = 0.02, time = 10.0, angle = omega * time;
    plate.motion.addRotation(0.0, 100.0, Vec3(0, 0, 0), Vec3(0, 1, 0), omega);
    // R_y(angle) by hand.
    dem::Mat3 rotation;
    rotation << std::cos(angle), 0, std::sin(angle), 0, 1, 0, -std::sin(angle), 0, std::cos(angle);
    const Vec3 surfacePoint = rotation * Vec3(0.6, 0.3, 0), normal = rotation * Vec3(0, 0, 1);
    std::vector<WallContact> contacts;
    plate.findContacts(surfacePoint + 0.07 * normal, 0.1, time, contacts);
    ASSERT_EQ(contacts.size(), 1u);
    // Eigen's angle-axis matrix and the hand-written one differ by rounding (~1e-15).
    expectVectorNear(contacts[0].point, surfacePoint, 1e-14);
    expectVectorNear(contacts[0].normal, normal, 1e-14);
    EXPECT_NEAR(contacts[0].overlap, 0.03, 1e-15);
    expectVectorNear(contacts[0].wallVelocity, Vec3(0, omega, 0).cross(surfacePoint), 1e-17);
    EXPECT_EQ(contacts[0].feature, 0);
    const dem::Wall floor{"floor", dem::PlaneWall(Vec3(0, 0, 0), Vec3(0, 0, 1)), dem::WallMotion(), 0};
    EXPECT_TRUE(floor.boundingBox(0.0).isUnbounded());
}

TEST(Wall, LiftedCylinderMovesWithItsMotion) {
    // Repose-angle test: the 43 mm steel cylinder is lifted at 5 mm/s from t = 1 s.
    dem::Wall cylinder{"repose cylinder",
                       dem::CylinderWall(Vec3(0, 0, 0), Vec3(0, 0, 1), 0.0215, 0.0, 0.05, dem::CylinderWall::Side::Inside),
                       dem::WallMotion(), 0};
    cylinder.motion.addTranslation(1.0, 21.0, Vec3(0, 0, 0.005));
    std::vector<WallContact> contacts;
    // At t = 3 s the tube spans z in [0.01, 0.06]; a sphere at z = 0.012 near the wall touches the lateral surface.
    cylinder.findContacts(Vec3(0.0205, 0, 0.012), 0.0015, 3.0, contacts);
    ASSERT_EQ(contacts.size(), 1u);
    EXPECT_NEAR(contacts[0].overlap, 0.0005, 1e-15);
    expectVectorNear(contacts[0].point, Vec3(0.0215, 0, 0.012), 1e-15);
    expectVectorNear(contacts[0].normal, Vec3(-1, 0, 0), 1e-15);
    expectVectorNear(contacts[0].wallVelocity, Vec3(0, 0, 0.005), 1e-18);
    // The same sphere below the lifted tube's lower rim touches the rim instead.
    contacts.clear();
    cylinder.findContacts(Vec3(0.0205, 0, 0.0095), 0.0015, 3.0, contacts);
    ASSERT_EQ(contacts.size(), 1u);
    EXPECT_EQ(contacts[0].feature, dem::CylinderWall::lowerRimFeature);
    EXPECT_NEAR(contacts[0].overlap, 0.0015 - std::hypot(0.001, 0.0005), 1e-15);
    const dem::BoundingBox box = cylinder.boundingBox(3.0);
    expectVectorNear(box.lower, Vec3(-0.0215, -0.0215, 0.01), 1e-15);
    expectVectorNear(box.upper, Vec3(0.0215, 0.0215, 0.06), 1e-15);
}

// The fastest wall material of each motion segment (case setup refuses a wall
// faster than impactVelocity): |v| of a translation; |omega| x the farthest
// point from the axis of a rotation, a mesh by its vertices, and no farther
// than the domain's corners; a turning plane without a domain is unbounded.
TEST(Wall, LargestSpeedOfEachMotionSegment) {
    dem::Wall plate{"plate", dem::MeshWall(std::make_shared<const dem::TriangleMesh>(squareTriangles(1.0, 1))),
                    dem::WallMotion(), 1};
    plate.motion.addTranslation(0.0, 1.0, Vec3(3.0, 4.0, 0.0));
    // Turns about the y axis through (2, 0, 0) after the unit square (x, y in [0, 1], z = 0) moved
    // by (3, 4, 0): its vertices lie 1 to 2 from the axis in x, so the farthest is 2 away.
    plate.motion.addRotation(2.0, 3.0, Vec3(2.0, 0.0, 0.0), Vec3(0.0, 1.0, 0.0), 0.5);
    EXPECT_DOUBLE_EQ(plate.largestSpeed(0, nullptr), 5.0);
    EXPECT_DOUBLE_EQ(plate.largestSpeed(1, nullptr), 0.5 * 2.0);
    // A domain whose farthest corner lies 1.5 from the axis bounds it.
    const dem::AxisAlignedBox domain{Vec3(2.5, -1.0, -1.0), Vec3(3.5, 1.0, 1.0)};
    EXPECT_DOUBLE_EQ(plate.largestSpeed(1, &domain), 0.5 * std::hypot(1.5, 1.0));
    // Removed before the turn starts: it moves nothing.
    plate.motion.setRemovalTime(1.5);
    EXPECT_EQ(plate.largestSpeed(1, nullptr), 0.0);

    dem::Wall floor{"floor", dem::PlaneWall(Vec3(0, 0, 0), Vec3(0, 0, 1)), dem::WallMotion(), 0};
    floor.motion.addRotation(0.0, 1.0, Vec3(0, 0, 0), Vec3(1, 0, 0), -2.0);
    EXPECT_TRUE(std::isinf(floor.largestSpeed(0, nullptr)));
    const dem::AxisAlignedBox cube{Vec3(-1, -1, -1), Vec3(1, 1, 1)};
    EXPECT_DOUBLE_EQ(floor.largestSpeed(0, &cube), 2.0 * std::sqrt(2.0));

    // A tube of radius 0.5 around the z axis turning about the x axis: its box's
    // corners (+-0.5, +-0.5, 0 or 2) lie up to hypot(0.5, 2) from it.
    dem::Wall tube{"tube", dem::CylinderWall(Vec3(0, 0, 0), Vec3(0, 0, 1), 0.5, 0.0, 2.0, dem::CylinderWall::Side::Inside),
                   dem::WallMotion(), 0};
    tube.motion.addRotation(0.0, 1.0, Vec3(0, 0, 0), Vec3(1, 0, 0), 3.0);
    EXPECT_DOUBLE_EQ(tube.largestSpeed(0, nullptr), 3.0 * std::hypot(0.5, 2.0));
}

TEST(ParticleWallCandidates, MovingMeshListedWithinItsTravelGivesTheContactsOfTheWholeMesh) {
    // A mesh wall under way (a ball translating, then turning about an axis
    // off its centre) is listed by triangles within radius + skin + allowance
    // of each particle, and the lists are built again once any point of it may
    // have moved the allowance.  Until then a particle has moved at most the
    // skin since the build (a build between two neighbour-list builds), so the
    // listed search must give the whole mesh's contacts, bit for bit.
    dem::WallMotion motion;
    motion.addTranslation(0.0, 0.5, Vec3(1.0, 0.5, 0.0));
    motion.addRotation(0.5, 1.0, Vec3(0.3, 0.0, 0.0), Vec3(0.2, 0.1, 1.0), 2.0);
    const std::vector<dem::Wall> walls{
        {"ball", dem::MeshWall(std::make_shared<const dem::TriangleMesh>(uvSphereTriangles(50, 50))), motion, 0}};
    const double radius = 0.05, skin = 0.02, allowance = 0.5 * skin, dt = 1e-5;
    std::mt19937_64 rng(41);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    long contacts = 0, reachedByTheAllowance = 0;
    for (const double built : {0.1, 0.6}) {
        // Particles around the ball where it is at the build, their gaps to
        // its surface spread over [-r/2, skin + allowance + 0.02], half of them
        // in [skin, skin + allowance].
        const dem::RigidTransform pose = motion.at(built);
        dem::ParticleStore particles;
        std::vector<double> gapAtBuild;
        for (int i = 0; i < 4000; ++i) {
            const double gap = i % 2 ? -0.5 * radius + (0.5 * radius + skin + allowance + 0.02) * uniform(rng)
                                     : skin + allowance * uniform(rng);  // only the allowance lists these
            particles.add(i, pose.apply((1.0 + radius + gap) * randomUnit(rng)), Vec3::Zero(), radius, 2500, 0);
            gapAtBuild.push_back(gap);
        }
        dem::ParticleWallCandidates candidates;
        candidates.build(particles, walls, built, skin, allowance);
        EXPECT_TRUE(candidates.movingWalls().empty());  // listed by triangles instead
        // The last time the lists still hold.
        double t = built;
        while (!candidates.movedTooFar(walls, t + dt) && t < built + 0.2) t += dt;
        ASSERT_LT(t, built + 0.2) << "never asked for a rebuild";
        if (built < 0.5) {
            // A translation at |v| = 1.118 m/s: the bound is the travel itself.
            EXPECT_NEAR(t - built, allowance / std::sqrt(1.25), 2 * dt);
        }
        // Each particle moved by the skin straight at the ball's centre now.
        const Vec3 centreNow = motion.at(t).translation;
        dem::WallProximityQuery query(walls, t);
        for (int i = 0; i < int(particles.size()); ++i) {
            const Vec3 x = particles.position[i] + skin * (centreNow - particles.position[i]).normalized();
            std::vector<std::pair<int, WallContact>> listed, whole;
            query.forEachNearIn(candidates, i, x, radius, 0.0,
                                [&](int w, const WallContact& c) { listed.emplace_back(w, c); });
            query.forEachNear(x, radius, 0.0, [&](int w, const WallContact& c) { whole.emplace_back(w, c); });
            ASSERT_EQ(listed.size(), whole.size()) << "particle " << i << ", gap at build " << gapAtBuild[i];
            for (std::size_t k = 0; k < whole.size(); ++k) {
                EXPECT_EQ(listed[k].second.feature, whole[k].second.feature);
                EXPECT_EQ(listed[k].second.overlap, whole[k].second.overlap);
                EXPECT_EQ(listed[k].second.point, whole[k].second.point);
            }
            contacts += long(whole.size());
            if (!whole.empty() && gapAtBuild[i] > skin) ++reachedByTheAllowance;
        }
    }
    // Not vacuous: contacts, some of them of particles the skin alone would not have listed.
    EXPECT_GT(contacts, 1000);
    EXPECT_GT(reachedByTheAllowance, 20);
}

TEST(ParticleWallCandidates, SimulationFindsAMovingMeshThatWasOutOfReachAtTheBuild) {
    // One sphere at rest without gravity never moves far enough to rebuild its
    // neighbour list; a plate of triangles 4 mm below it rises at 2 m/s from
    // the start (contact from 2 ms).  Out of reach at the build, the plate is
    // found only because the wall lists are built again as it travels.
    dem::WallMotion rise;
    rise.addTranslation(0.0, 1.0, Vec3(0, 0, 2.0));
    std::vector<Triangle> square = squareTriangles(0.02, 2);
    for (Triangle& tri : square)
        for (Vec3& v : tri) v -= Vec3(0.01, 0.01, 0.0);
    dem::Simulation sim = sandWithoutGravity(
        {{"plate", dem::MeshWall(std::make_shared<const dem::TriangleMesh>(square)), rise, 0}});
    sim.insert({{Vec3(0, 0, 0.005), 0.001}}, 0, Vec3::Zero());
    sim.step(1900);  // to 1.9 ms
    EXPECT_EQ(sim.pairList().buildCount(), 1);
    EXPECT_EQ(sim.particles().velocity[0].z(), 0.0);
    sim.step(3100);  // to 5 ms
    // Pushed ahead of the plate: at least its speed (about 1.5x it for e = 0.5).
    EXPECT_GT(sim.particles().velocity[0].z(), 2.0);
}
