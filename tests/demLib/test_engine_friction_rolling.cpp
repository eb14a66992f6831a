// Verification of dem::Simulation's tangential and rolling contact laws on a
// single sphere and a plane wall, against rigid-body closed forms: the
// sliding angle atan(mu) of a sphere that cannot roll, and the stopping
// distance of a sphere rolling against a constant resisting torque.
#include <gtest/gtest.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "demLib/simulation.hpp"
#include "thread_count.hpp"

namespace {

using dem::Vec3;

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadius = 1e-3;
constexpr double kG = 9.81;

dem::Material glass() { return {"glass", 5e6, 0.3, 2500.0}; }

// One sphere resting on the plane z = 0 (normal +z) after `settleTime`.
dem::Simulation sphereOnFloor(double friction, double rollingFriction, dem::RollingModel model,
                              const Vec3& gravity, double dt, double settleTime) {
    const std::vector<dem::Material> mats{glass()};
    dem::PairCoefficients c;
    c.restitution = 0.5;
    c.friction = friction;
    c.rollingFriction = rollingFriction;
    dem::InteractionTable table(1);
    table.set(mats, 0, 0, c);
    dem::SimulationSettings s;
    s.timeStep = dt;
    s.gravity = gravity;
    s.forces.rolling = model;
    s.source = "test_engine_friction_rolling";
    std::vector<dem::Wall> walls{dem::Wall{"floor", dem::PlaneWall(Vec3::Zero(), Vec3::UnitZ()), {}, 0}};
    dem::Simulation sim(s, mats, table, walls);
    sim.insert({{Vec3(0, 0, kRadius), kRadius}}, 0, Vec3::Zero());
    sim.step(static_cast<long>(settleTime / dt));
    return sim;
}

// ---------------------------------------------------------------------------
// 3. Onset of sliding.  A sphere that cannot roll rests on a plane whose
// inclination theta grows slowly; on a rigid incline it sticks while
// m g sin(theta) <= mu m g cos(theta), i.e. until theta = atan(mu).
//
// The plane stays fixed and the gravity vector turns instead (an external
// force m g (sin theta, 0, -cos theta) set every step; settings.gravity = 0):
// the same mechanics in the plane's frame, without the wall velocity a
// rotating wall would add.  Rolling is blocked by EPSD2 with mu_r = 5: its
// spring torque can reach mu_r R Fn, far above the R m g sin(theta) the
// friction force asks for, so the sphere turns only by the spring's elastic
// angle.  (CDT with a large mu_r is not used: its torque has constant
// magnitude and flips sign with omega every step, so a resting sphere
// chatters instead of sticking.)
//
// "Starts to slide": the centre has moved 0.01 R down the slope since the
// tilt began.  Before sliding it moves only by the elastic tangential and
// rolling springs, (1 + 1) m g sin(theta) / kt ~ 5e-7 m = 5e-4 R here.  After
// the onset the sphere accelerates with a ~ g (theta - theta_c) / cos(theta_c),
// so at the tilt rate Omega it covers 0.01 R after a lag
// (6 * 0.01 R cos(theta_c) Omega^2 / g)^(1/3) ~ 0.07 deg for Omega = 0.02 rad/s.

struct SlideOnset {
    double angleDeg;       // inclination when the centre had moved 0.01 R
    double speedToSpin;    // |v| / (R |omega|) at that moment (>> 1: sliding, not rolling)
    double creepBeforeDeg; // displacement / R half a degree before atan(mu)
};

SlideOnset slideOnset(double mu) {
    const double dt = 1e-5;
    const double thetaC = std::atan(mu);
    const double theta0 = thetaC - 3.0 * kPi / 180.0;
    const double tiltRate = 0.02;  // rad/s
    const double m = glass().density * 4.0 / 3.0 * kPi * kRadius * kRadius * kRadius;
    auto gravityAt = [&](double theta) { return Vec3(m * kG * std::sin(theta), 0.0, -m * kG * std::cos(theta)); };

    dem::Simulation sim = sphereOnFloor(mu, 5.0, dem::RollingModel::EPSD2, Vec3::Zero(), dt, 0.0);
    sim.particles().externalForce[0] = gravityAt(theta0);
    sim.step(static_cast<long>(0.05 / dt));  // settle on the plane at theta0 < theta_c
    EXPECT_EQ(sim.lastStep().contacts.wallContacts, 1u);

    const double x0 = sim.particles().position[0].x();
    const double t0 = sim.time();
    SlideOnset result{std::nan(""), 0.0, 0.0};
    const double thetaEnd = thetaC + 2.0 * kPi / 180.0;
    for (double theta = theta0; theta < thetaEnd;) {
        theta = theta0 + tiltRate * (sim.time() - t0);
        sim.particles().externalForce[0] = gravityAt(theta);
        sim.step(1);
        const double moved = sim.particles().position[0].x() - x0;
        if (theta < thetaC - 0.5 * kPi / 180.0) result.creepBeforeDeg = moved / kRadius;
        if (moved > 0.01 * kRadius) {
            result.angleDeg = theta * 180.0 / kPi;
            result.speedToSpin =
                sim.particles().velocity[0].norm() / (kRadius * sim.particles().omega[0].norm() + 1e-300);
            break;
        }
    }
    EXPECT_EQ(sim.lastStep().contacts.wallContacts, 1u) << "the sphere lost the plane";
    return result;
}

TEST(EngineFriction, BlockedSphereSlidesAtArctanMu) {
    OneThread oneThread;
    for (double mu : {0.3, 0.61}) {
        const SlideOnset onset = slideOnset(mu);
        const double expected = std::atan(mu) * 180.0 / kPi;
        std::printf("mu %.2f: slides at %.3f deg, atan(mu) = %.3f deg, |v|/(R|w|) = %.1f, creep %.2e R\n", mu,
                    onset.angleDeg, expected, onset.speedToSpin, onset.creepBeforeDeg);
        EXPECT_NEAR(onset.angleDeg, expected, 0.5) << "mu = " << mu;
        // It slides, it does not roll: the contact point moves with the centre.
        EXPECT_GT(onset.speedToSpin, 10.0);
        // Half a degree below the limit the sphere still sticks.
        EXPECT_LT(onset.creepBeforeDeg, 2e-3);
    }
}

// ---------------------------------------------------------------------------
// 4. Rolling resistance.  A sphere rolls without slipping on a horizontal
// plane with speed v0 against a resisting torque of constant magnitude
// M = mu_r R m g (EPSD2 once its spring is fully mobilised; CDT always).
// With f the friction force at the contact (along +x, motion along +x):
//     m dv/dt = f,      I dw/dt = -f R - M,      v = w R  (no slip),
// so (m + I/R^2) dv/dt = -M/R and with I = 2/5 m R^2:
//     dv/dt = -mu_r g / 1.4,   s = v0^2 / (2 |dv/dt|) = 1.4 v0^2 / (2 mu_r g).
// No slip needs |f| = mu_r m g (1 - 1/1.4) <= mu m g: mu = 0.61 > 0.36 mu_r.
//
// LIGGGHTS' wall variants: EPSD2 limits the spring at mu_r R |Fn| (lever
// arm R) but feeds it w (R - d/2)/(R - d); CDT uses the lever arm R - d/2 and
// the elastic force kn d.  Both only change M by O(d/R) = 1e-3 here (d ~ 1 um
// under the sphere's weight), so the closed form holds to 0.1 %.
// The friction force's own torque uses the lever arm R - d/2, which changes
// the no-slip ratio v/w by the same 1e-3.

double stopDistanceRatio(dem::RollingModel model, double rollingFriction, double v0) {
    const double dt = 1e-5;
    dem::Simulation sim =
        sphereOnFloor(0.61, rollingFriction, model, Vec3(0, 0, -kG), dt, 0.05);
    sim.particles().velocity[0] = Vec3(v0, 0, 0);
    sim.particles().omega[0] = Vec3(0, v0 / kRadius, 0);  // contact point at rest: v - R w x n = 0
    const double x0 = sim.particles().position[0].x();
    const double expected = 1.4 * v0 * v0 / (2.0 * rollingFriction * kG);
    const double stopTime = v0 / (rollingFriction * kG / 1.4);
    sim.step(static_cast<long>(1.3 * stopTime / dt));
    EXPECT_LT(std::abs(sim.particles().velocity[0].x()), 1e-3 * v0) << "still rolling";
    EXPECT_EQ(sim.lastStep().contacts.wallContacts, 1u);
    return (sim.particles().position[0].x() - x0) / expected;
}

TEST(EngineRolling, Epsd2StopsAtAnalyticDistance) {
    OneThread oneThread;
    for (auto [muR, v0] : {std::pair{0.1, 0.1}, std::pair{0.5, 0.2}}) {
        const double ratio = stopDistanceRatio(dem::RollingModel::EPSD2, muR, v0);
        std::printf("EPSD2 mu_r %.2f v0 %.2f: s / s_analytic = %.5f\n", muR, v0, ratio);
        EXPECT_NEAR(ratio, 1.0, 2e-3) << "mu_r = " << muR;  // measured within 4e-4
    }
}

TEST(EngineRolling, CdtStopsAtAnalyticDistance) {
    OneThread oneThread;
    for (auto [muR, v0] : {std::pair{0.1, 0.1}, std::pair{0.5, 0.2}}) {
        const double ratio = stopDistanceRatio(dem::RollingModel::CDT, muR, v0);
        std::printf("CDT   mu_r %.2f v0 %.2f: s / s_analytic = %.5f\n", muR, v0, ratio);
        EXPECT_NEAR(ratio, 1.0, 2e-3) << "mu_r = " << muR;  // measured within 4e-4
    }
}

// Without rolling resistance the sphere keeps rolling: v stays v0 (a wrong
// torque sign or lever arm would slow it or make it slip).
TEST(EngineRolling, NoResistanceKeepsRolling) {
    OneThread oneThread;
    const double dt = 1e-5;
    const double v0 = 0.1;
    dem::Simulation sim = sphereOnFloor(0.61, 0.0, dem::RollingModel::None, Vec3(0, 0, -kG), dt, 0.05);
    sim.particles().velocity[0] = Vec3(v0, 0, 0);
    sim.particles().omega[0] = Vec3(0, v0 / kRadius, 0);
    sim.step(static_cast<long>(0.1 / dt));
    std::printf("no rolling resistance: v/v0 = %.6f after 0.1 s\n", sim.particles().velocity[0].x() / v0);
    EXPECT_NEAR(sim.particles().velocity[0].x() / v0, 1.0, 1e-3);
    EXPECT_NEAR(sim.particles().omega[0].y() * kRadius / v0, 1.0, 2e-3);
}

}  // namespace
