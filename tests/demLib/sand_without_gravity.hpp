#pragma once
// One sand material (E = 5 MPa, e = 0.5, mu = 0.5), no gravity, a step of 1e-6 s:
// a simulation for the tests that only need contacts to happen somewhere.
#include <utility>
#include <vector>

#include "demLib/simulation.hpp"

// The same sand with the settings as given (time step, gravity).
inline dem::Simulation sandSimulation(std::vector<dem::Wall> walls, const dem::SimulationSettings& settings) {
    const std::vector<dem::Material> materials{{"sand", 5e6, 0.3, 2500.0}};
    dem::InteractionTable table(1);
    dem::PairCoefficients coefficients;
    coefficients.restitution = 0.5;
    coefficients.friction = 0.5;
    table.set(materials, 0, 0, coefficients);
    return dem::Simulation(settings, materials, table, std::move(walls));
}

inline dem::Simulation sandWithoutGravity(std::vector<dem::Wall> walls = {}, dem::SimulationSettings settings = {}) {
    settings.timeStep = 1e-6;
    settings.gravity = dem::Vec3::Zero();
    return sandSimulation(std::move(walls), settings);
}
