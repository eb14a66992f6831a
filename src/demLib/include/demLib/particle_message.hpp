#pragma once
// One particle's fields in a message between ranks: the ghost exchange, migration and the
// gathered particle output all pack and unpack them here.
#include <cstdint>

#include "demLib/byte_buffer.hpp"
#include "demLib/particle_store.hpp"

namespace dem {

// Every ParticleStore field, in one place: a field added to the store must be
// added here too, or migrating particles would lose it.
inline void packParticle(ByteWriter& w, const ParticleStore& p, std::size_t i) {
    w.put(p.id[i]);
    w.put(p.position[i]);
    w.put(p.velocity[i]);
    w.put(p.omega[i]);
    w.put(p.force[i]);
    w.put(p.torque[i]);
    w.put(p.radius[i]);
    w.put(p.mass[i]);
    w.put(p.material[i]);
    w.put(p.externalForce[i]);  // const: reading does not allocate
}

inline void unpackParticle(ByteReader& r, ParticleStore& p) {
    p.id.push_back(r.get<std::int64_t>());
    p.position.push_back(r.vec());
    p.velocity.push_back(r.vec());
    p.omega.push_back(r.vec());
    p.force.push_back(r.vec());
    p.torque.push_back(r.vec());
    p.radius.push_back(r.get<double>());
    p.mass.push_back(r.get<double>());
    p.material.push_back(r.get<int>());
    p.externalForce.push_back(r.vec());
}

}  // namespace dem
