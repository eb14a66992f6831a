#pragma once
// Particle beds shared by the domain decomposition tests (serial and MPI):
// each is a pure function of its arguments, so every rank builds the same one.
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "demLib/simulation.hpp"

namespace decomposition_cases {

using dem::Vec3;

inline dem::Material glass() { return {"glass", 5e6, 0.3, 2500.0}; }

inline dem::Wall planeWall(const std::string& name, const Vec3& point, const Vec3& normal) {
    return dem::Wall{name, dem::PlaneWall(point, normal), dem::WallMotion(), 0};
}

struct Case {
    dem::SimulationSettings settings;
    std::vector<dem::Material> materials{glass()};
    dem::InteractionTable table{1};
    std::vector<dem::Wall> walls;
    std::vector<dem::InsertedParticle> particles;
    double speed = 0.0;  // velocity components uniform in [-speed, speed]
    double spin = 0.0;   // spin components uniform in [-spin, spin]
    double shear = 0.0;  // plus +-shear along x, alternating with the lattice layer in z
    double spacing = 0.0;
    double xLower = 0.0, xUpper = 0.0;  // span of the centres along x
    double waterContent = 0.0;          // > 0: capillary liquid added after insertion

    dem::Simulation make() const { return dem::Simulation(settings, materials, table, walls); }
};

// Initial velocity and spin of particle `id`: a function of the id only, so a
// decomposed run gives each owned particle the same state as the serial run.
inline void setMotionById(dem::Simulation& sim, const Case& c) {
    dem::ParticleStore& p = sim.particles();
    for (std::size_t i = 0; i < sim.ownedCount(); ++i) {
        std::mt19937_64 rng(0x9e3779b97f4a7c15ULL ^ static_cast<std::uint64_t>(p.id[i]));
        std::uniform_real_distribution<double> u(-1.0, 1.0);
        const double vx = u(rng), vy = u(rng), vz = u(rng);
        const double wx = u(rng), wy = u(rng), wz = u(rng);
        p.velocity[i] = c.speed * Vec3(vx, vy, vz);
        const long layer = std::lround(p.position[i].z() / c.spacing);
        p.velocity[i].x() += layer % 2 == 0 ? c.shear : -c.shear;
        p.omega[i] = c.spin * Vec3(wx, wy, wz);
    }
}

// nx x ny x nz spheres of radius 1 mm +- 2 % on a jittered cubic lattice of
// the given spacing (< 2 mm: neighbours overlap), friction, EPSD rolling
// resistance and a floor and four side walls close around the bed.
inline Case lattice(int nx, int ny, int nz, double spacing, double dt, unsigned seed) {
    Case c;
    c.spacing = spacing;
    c.settings.timeStep = dt;
    c.settings.source = "decomposition test";
    c.settings.forces.rolling = dem::RollingModel::EPSD;
    dem::PairCoefficients k;
    k.restitution = 0.5;
    k.friction = 0.5;
    k.rollingFriction = 0.1;
    k.rollingViscousDamping = 0.3;
    c.table.set(c.materials, 0, 0, k);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int z = 0; z < nz; ++z)
        for (int y = 0; y < ny; ++y)
            for (int x = 0; x < nx; ++x) {
                const Vec3 jitter = 0.01 * spacing * Vec3(u(rng), u(rng), u(rng));
                c.particles.push_back({Vec3(x, y, z) * spacing + jitter, 1e-3 * (1.0 + 0.02 * u(rng))});
            }
    const double margin = 1.1e-3;  // clear of every sphere at insertion
    const Vec3 hi = Vec3(nx - 1, ny - 1, nz - 1) * spacing;
    c.walls.push_back(planeWall("floor", Vec3(0, 0, -margin), Vec3(0, 0, 1)));
    c.walls.push_back(planeWall("left", Vec3(-margin, 0, 0), Vec3(1, 0, 0)));
    c.walls.push_back(planeWall("right", Vec3(hi.x() + margin, 0, 0), Vec3(-1, 0, 0)));
    c.walls.push_back(planeWall("front", Vec3(0, -margin, 0), Vec3(0, 1, 0)));
    c.walls.push_back(planeWall("back", Vec3(0, hi.y() + margin, 0), Vec3(0, -1, 0)));
    c.xLower = 0.0;
    c.xUpper = hi.x();
    return c;
}

// A dense bed at rest-ish: overlapping neighbours, slow random motion.
inline Case overlappingBed() {
    Case c = lattice(8, 8, 6, 1.97e-3, 2e-6, 11);
    c.speed = 0.05;
    c.spin = 50.0;
    return c;
}

// A granular gas in an open-topped box: fast random motion, layers sheared
// against each other along x, many collisions, particles crossing slab faces
// and some leaving the domain at the top.
inline Case agitatedGas() {
    Case c = lattice(8, 6, 6, 2.3e-3, 5e-6, 23);
    c.speed = 1.0;
    c.shear = 1.5;
    c.spin = 300.0;
    dem::AxisAlignedBox box;
    box.min = Vec3(-1, -1, -1);
    box.max = Vec3(1, 1, 5 * 2.3e-3 + 1.5e-3);
    c.settings.domain = box;
    return c;
}

// The agitated gas made wet: capillary bridges (paper's rule, the liquid
// shared over all bridges of the run) between most neighbours, wall bridges
// on the floor and sides, bridges breaking and forming as the layers shear,
// and particles (with their bridges) lost through the open top.
inline Case wetGas() {
    Case c = agitatedGas();
    c.settings.forces.cohesion = dem::CohesionModel::Capillary;
    c.settings.forces.wallBridges = true;
    c.waterContent = 0.02;
    return c;
}

}  // namespace decomposition_cases
