#include "demLib/particle_store.hpp"

#include <algorithm>
#include <cmath>

#include "demLib/constants.hpp"

namespace dem {

std::size_t ParticleStore::add(std::int64_t globalId, const Vec3& x, const Vec3& v, double r,
                               double density, int materialIndex) {
    const double m = density * 4.0 / 3.0 * pi * r * r * r;
    id.push_back(globalId);
    position.push_back(x);
    velocity.push_back(v);
    omega.push_back(Vec3::Zero());
    force.push_back(Vec3::Zero());
    torque.push_back(Vec3::Zero());
    radius.push_back(r);
    mass.push_back(m);
    material.push_back(materialIndex);
    ++externalForce.count_;
    if (externalForce.allocated()) externalForce.values_.push_back(Vec3::Zero());
    return id.size() - 1;
}

namespace {
template <class T>
void keepIf(std::vector<T>& field, const std::vector<char>& keep) {
    std::size_t k = 0;
    for (std::size_t i = 0; i < field.size(); ++i)
        if (keep[i]) field[k++] = field[i];
    field.resize(k);
}

template <class T>
void reorder(std::vector<T>& field, const std::vector<int>& order) {
    std::vector<T> out(order.size());
    for (std::size_t k = 0; k < order.size(); ++k) out[k] = field[order[k]];
    field.swap(out);
}
}  // namespace

std::vector<int> ParticleStore::compact(const std::vector<char>& keep) {
    std::vector<int> oldToNew(size(), -1);
    int k = 0;
    for (std::size_t i = 0; i < size(); ++i)
        if (keep[i]) oldToNew[i] = k++;
    keepIf(id, keep);
    keepIf(position, keep);
    keepIf(velocity, keep);
    keepIf(omega, keep);
    keepIf(force, keep);
    keepIf(torque, keep);
    keepIf(radius, keep);
    keepIf(mass, keep);
    keepIf(material, keep);
    if (externalForce.allocated()) keepIf(externalForce.values_, keep);
    externalForce.count_ = id.size();
    return oldToNew;
}

void ParticleStore::permute(const std::vector<int>& order) {
    reorder(id, order);
    reorder(position, order);
    reorder(velocity, order);
    reorder(omega, order);
    reorder(force, order);
    reorder(torque, order);
    reorder(radius, order);
    reorder(mass, order);
    reorder(material, order);
    if (externalForce.allocated()) reorder(externalForce.values_, order);
    externalForce.count_ = id.size();
}

void ParticleStore::reserve(std::size_t n) {
    id.reserve(n);
    position.reserve(n);
    velocity.reserve(n);
    omega.reserve(n);
    force.reserve(n);
    torque.reserve(n);
    radius.reserve(n);
    mass.reserve(n);
    material.reserve(n);
    if (externalForce.allocated()) externalForce.values_.reserve(n);
}

double ParticleStore::totalMass() const {
    double m = 0.0;
    for (double mi : mass) m += mi;
    return m;
}

double ParticleStore::kineticEnergy(std::size_t count) const {
    double e = 0.0;
    for (std::size_t i = 0; i < std::min(count, size()); ++i)
        e += 0.5 * mass[i] * velocity[i].squaredNorm() +
             0.5 / (1.0 / (0.4 * mass[i] * radius[i] * radius[i])) * omega[i].squaredNorm();
    return e;
}

std::size_t ParticleStore::bytesPerParticle() const {
    return sizeof(std::int64_t) + 5 * sizeof(Vec3) + 2 * sizeof(double) + sizeof(int) +
           (externalForce.allocated() ? sizeof(Vec3) : 0);
}

void ExternalForceField::assign(std::vector<Vec3> values) {
    count_ = values.size();
    values_.clear();
    for (const Vec3& v : values)
        if (!v.isZero(0.0)) {
            values_.swap(values);
            return;
        }
    values_.shrink_to_fit();
}

}  // namespace dem
