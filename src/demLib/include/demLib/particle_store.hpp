#pragma once
// Particles as a structure of arrays (Cabana / LAMMPS style): one std::vector per
// named field, so the hot loops stream through contiguous memory.
#include <cstdint>
#include <vector>

#include "demLib/vec3.hpp"

namespace dem {

// A per-particle force field that is allocated on its first write: dry DEM
// runs never set one and so do not pay 24 bytes per particle for zeros.
// Reads of an unallocated field give zero.  Its length follows the store.
class ExternalForceField {
public:
    bool allocated() const { return !values_.empty(); }
    std::size_t size() const { return count_; }
    Vec3 operator[](std::size_t i) const { return values_.empty() ? Vec3::Zero() : values_[i]; }
    // Write access: allocates zeros for every particle on first use.
    Vec3& operator[](std::size_t i) {
        if (values_.empty()) values_.assign(count_, Vec3::Zero());
        return values_[i];
    }
    // All values (zeros when unallocated), e.g. for a restart file.
    std::vector<Vec3> toVector() const {
        return values_.empty() ? std::vector<Vec3>(count_, Vec3::Zero()) : values_;
    }
    // Takes n values; stays unallocated when all are zero.
    void assign(std::vector<Vec3> values);
    // One more particle (a migrating one) with value v; allocates only when v is not zero.
    void push_back(const Vec3& v) {
        if (values_.empty() && !v.isZero(0.0)) values_.assign(count_, Vec3::Zero());
        if (!values_.empty()) values_.push_back(v);
        ++count_;
    }
    std::size_t bytes() const { return values_.capacity() * sizeof(Vec3); }

private:
    friend class ParticleStore;
    std::size_t count_ = 0;
    std::vector<Vec3> values_;  // empty, or count_ entries
};

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
    std::vector<double> mass;  // 1/m and 1/I = 1/(2/5 m r^2) are recomputed where needed
    std::vector<int> material;
    // Forces from outside the DEM (fluid drag, buoyancy), held until replaced;
    // no memory until a coupling first writes one.
    ExternalForceField externalForce;

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
    // Translational + rotational, of all particles or of the first `count`
    // (the owned ones of a decomposed run, which stores its ghosts after them).
    double kineticEnergy() const { return kineticEnergy(size()); }
    double kineticEnergy(std::size_t count) const;
    // Bytes of the per-particle fields (externalForce counted once allocated).
    std::size_t bytesPerParticle() const;
};

}  // namespace dem
