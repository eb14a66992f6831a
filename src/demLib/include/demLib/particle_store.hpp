#pragma once
// Particles as a structure of arrays (Cabana / LAMMPS style): one std::vector per
// named field, so the hot loops stream through contiguous memory.
#include <cstdint>
#include <vector>

#include "demLib/vec3.hpp"

namespace dem {

class ParticleStore {
public:
    // Global, never-reused identity: contact history and restart files key on it,
    // and it survives reordering and (later) migration between MPI ranks.
    std::vector<std::int64_t> id;
    std::vector<Vec3> position;
    std::vector<Vec3> velocity;
    std::vector<Vec3> omega;
    std::vector<Vec3> force;
    std::vector<Vec3> torque;
    std::vector<double> radius;
    std::vector<double> mass;
    std::vector<double> invMass;
    std::vector<double> invInertia;  // solid sphere: I = 2/5 m r^2
    std::vector<int> material;
    // Forces from outside the DEM (fluid drag, buoyancy), held until replaced.
    std::vector<Vec3> externalForce;

    std::size_t size() const { return id.size(); }
    bool empty() const { return id.empty(); }

    // Appends a solid sphere at rest-or-moving; returns its index.
    std::size_t add(std::int64_t globalId, const Vec3& x, const Vec3& v, double r,
                    double density, int materialIndex);

    // Keeps the particles for which keep[i] is true, in order; returns the map
    // old index -> new index (-1 for removed ones).
    std::vector<int> compact(const std::vector<char>& keep);

    // Reorders all fields: new index k holds old particle order[k].
    void permute(const std::vector<int>& order);

    void reserve(std::size_t n);
    double totalMass() const;
    double kineticEnergy() const;  // translational + rotational
    std::size_t bytesPerParticle() const;
};

}  // namespace dem
