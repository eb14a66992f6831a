#include "demLib/contact_stability.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "demLib/constants.hpp"
#include "demLib/contact_rolling_resistance.hpp"

namespace dem {

namespace {


Eigen::Matrix3d crossMatrix(const Eigen::Vector3d& v) {
    Eigen::Matrix3d m;
    m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
    return m;
}

double sphereMass(double radius, double density) { return density * 4.0 / 3.0 * pi * radius * radius * radius; }

}  // namespace

LinearContact linearHertzContact(const InteractionProperties& props, double radiusEff, double massEff,
                                 double overlap, RollingModel rolling, double rollingInertia) {
    const double contactRadius = std::sqrt(radiusEff * overlap);  // a = sqrt(R* d)
    const double dampingScale = std::sqrt(contactRadius * massEff);
    LinearContact c;
    // The elastic force is (4/3 Y*) a d, so its tangent stiffness dF/dd is 1.5 times the secant one.
    c.normalStiffness = 1.5 * props.normalStiffnessFactor * contactRadius;
    c.tangentialStiffness = props.tangentialStiffnessFactor * contactRadius;
    c.normalDamping = props.normalDampingFactor * dampingScale;
    c.tangentialDamping = props.tangentialDampingFactor * dampingScale;
    if (rolling == RollingModel::EPSD2) {
        c.rollingStiffness = epsd2RollingStiffness(c.tangentialStiffness, radiusEff);
    } else if (rolling == RollingModel::EPSD) {
        // EPSD's stiffness is built on the secant normal stiffness, as in the contact law.
        c.rollingStiffness = epsdRollingStiffness(props.normalStiffnessFactor * contactRadius,
                                                  props.rollingFriction, radiusEff);
        c.rollingDamping = props.rollingViscousDamping * 2.0 * std::sqrt(rollingInertia * c.rollingStiffness);
    }
    return c;
}

void addContact(ContactClusterModel& model, double leverArm, const Eigen::Vector3d& normal,
                const LinearContact& contact) {
    const Eigen::Vector3d n = normal.normalized();
    const Eigen::Matrix3d normalPart = n * n.transpose();
    const Eigen::Matrix3d tangentPart = Eigen::Matrix3d::Identity() - normalPart;
    // Velocity of the contact point c n: v + w x (c n) = v - c [n]x w.  Its
    // tangential part is B_t q', its normal part B_n q'; a force F there acts on
    // q as (F, c n x F) = B^T F for either part, so each spring adds B^T k B.
    Eigen::Matrix<double, 3, 6> tangential;
    tangential << tangentPart, -leverArm * tangentPart * crossMatrix(n);
    Eigen::Matrix<double, 3, 6> normalRow;
    normalRow << normalPart, Eigen::Matrix3d::Zero();
    model.stiffness += contact.tangentialStiffness * tangential.transpose() * tangential +
                       contact.normalStiffness * normalRow.transpose() * normalRow;
    model.damping += contact.tangentialDamping * tangential.transpose() * tangential +
                     contact.normalDamping * normalRow.transpose() * normalRow;
    // The rolling spring resists the rotation's part in the tangent plane (neighbour fixed).
    model.stiffness.bottomRightCorner<3, 3>() += contact.rollingStiffness * tangentPart;
    model.damping.bottomRightCorner<3, 3>() += contact.rollingDamping * tangentPart;
}

ContactClusterModel cubicContactCluster(double radius, double mass, const LinearContact& contact, double leverArm) {
    ContactClusterModel model;
    const double inertia = 0.4 * mass * radius * radius;
    model.mass.diagonal() << mass, mass, mass, inertia, inertia, inertia;
    for (int axis = 0; axis < 3; ++axis)
        for (double side : {1.0, -1.0}) addContact(model, leverArm, side * Eigen::Vector3d::Unit(axis), contact);
    return model;
}

double verletSpectralRadius(const ContactClusterModel& model, double dt) {
    // With u = the half-step velocity v(n - 1/2), which the forces of step n
    // see: u' = u + dt a(x, u), x' = x + dt u',  a = -M^-1 (K x + C u).
    const Eigen::Matrix<double, 6, 6> massInverse = model.mass.inverse();
    const Eigen::Matrix<double, 6, 6> identity = Eigen::Matrix<double, 6, 6>::Identity();
    const Eigen::Matrix<double, 6, 6> velocityFromVelocity = identity - dt * massInverse * model.damping;
    const Eigen::Matrix<double, 6, 6> velocityFromPosition = -dt * massInverse * model.stiffness;
    Eigen::Matrix<double, 12, 12> step;
    step.topLeftCorner<6, 6>() = identity + dt * velocityFromPosition;
    step.topRightCorner<6, 6>() = dt * velocityFromVelocity;
    step.bottomLeftCorner<6, 6>() = velocityFromPosition;
    step.bottomRightCorner<6, 6>() = velocityFromVelocity;
    const Eigen::EigenSolver<Eigen::Matrix<double, 12, 12>> solver(step, false);
    return solver.eigenvalues().cwiseAbs().maxCoeff();
}

double verletStableTimeStep(const ContactClusterModel& model) {
    const Eigen::Matrix<double, 6, 6> massInverse = model.mass.inverse();
    // A model with a non-finite entry (from non-finite input) has no stable step.
    if (!model.mass.allFinite() || !model.stiffness.allFinite() || !model.damping.allFinite()) return 0.0;
    const double stiffest = (massInverse * model.stiffness).eigenvalues().cwiseAbs().maxCoeff();
    const double fastestDamping = (massInverse * model.damping).eigenvalues().cwiseAbs().maxCoeff();
    if (!(stiffest > 0.0) && !(fastestDamping > 0.0)) return std::numeric_limits<double>::infinity();
    // A neutral mode (a direction without a spring, e.g. the spin about a single
    // contact's normal) is a double eigenvalue 1 of a defective map, which the
    // eigensolver returns as 1 + a few 1e-7 (measured up to 5e-7); a growing mode
    // passes 1e-5 within a small fraction of a per cent beyond its limit.
    constexpr double tolerance = 1e-5;
    auto stable = [&](double dt) { return verletSpectralRadius(model, dt) <= 1.0 + tolerance; };
    // The undamped limit 2/w is an upper bound on the damped one; the doubling
    // only guards against a model whose bound is not reached there.
    double high = stiffest > 0.0 ? 2.0 / std::sqrt(stiffest) : 2.0 / fastestDamping;
    for (int k = 0; k < 60 && stable(high); ++k) high *= 2.0;
    double low = 0.0;
    while (high - low > 1e-9 * high) {
        const double mid = 0.5 * (low + high);
        (stable(mid) ? low : high) = mid;
    }
    return low;
}

int contactNumberAround(double ratio) {
    // Smallest ratio at which N spheres fit: 1 / sin(d_N / 2) - 1, d_N the
    // largest smallest angular distance of N points on a sphere (Tammes;
    // N = 11 fits no sooner than 12).
    static constexpr struct {
        double ratio;
        int count;
    } fits[] = {{0.902114, 12}, {0.832466, 10}, {0.732051, 9}, {0.645330, 8}, {0.591255, 7}, {0.414214, 6},
                {0.224745, 4}, {0.154701, 3}};  // rounded up
    for (const auto& f : fits)
        if (ratio >= f.ratio) return f.count;
    return 2;
}

double capillaryContactForceBound(double radius1, double radius2, const CapillaryParameters& capillary,
                                  double forceScale) {
    const double larger = std::max(radius1, radius2);
    double strongest = 0.0;
    for (double reducedVolume = 1e-5; reducedVolume <= 1.0001e-1; reducedVolume *= std::sqrt(10.0)) {
        const CapillaryBridgeFit fit =
            capillaryBridgeFit(radius1, radius2, reducedVolume * larger * larger * larger, capillary);
        strongest = std::max(strongest, std::abs(fit.contactForce));
    }
    return forceScale * strongest;
}

double capillaryClusterStableTimeStep(double radius, const Material& material, double neighbourRadius,
                                      const Material& neighbourMaterial, const InteractionProperties& props,
                                      const CapillaryParameters& capillary, double forceScale,
                                      RollingModel rolling, int neighbourCount) {
    const double mass = sphereMass(radius, material.density);
    const double neighbourMass = sphereMass(neighbourRadius, neighbourMaterial.density);
    const double radiusEff = radius * neighbourRadius / (radius + neighbourRadius);
    const double massEff = mass * neighbourMass / (mass + neighbourMass);
    const double force = capillaryContactForceBound(radius, neighbourRadius, capillary, forceScale);
    if (!(force > 0.0)) return std::numeric_limits<double>::infinity();
    // Hertz: F = (4/3 Y*) sqrt(R*) d^(3/2).
    const double overlap = std::pow(force / (props.normalStiffnessFactor * std::sqrt(radiusEff)), 2.0 / 3.0);
    const double rollingInertia = rollingInertiaEff(mass, radius, neighbourMass, neighbourRadius);
    LinearContact contact = linearHertzContact(props, radiusEff, massEff, overlap, rolling, rollingInertia);
    // The neighbours' motion (1 + m/m_n) and their number (N/6 on each of the cube's six).
    const double neighbours =
        neighbourCount > 0 ? neighbourCount : std::max(6, contactNumberAround(radius / neighbourRadius));
    const double scale = (1.0 + mass / neighbourMass) * neighbours / 6.0;
    for (double* part : {&contact.normalStiffness, &contact.tangentialStiffness, &contact.normalDamping,
                         &contact.tangentialDamping, &contact.rollingStiffness, &contact.rollingDamping})
        *part *= scale;
    return verletStableTimeStep(cubicContactCluster(radius, mass, contact, radius - 0.5 * overlap));
}

}  // namespace dem
