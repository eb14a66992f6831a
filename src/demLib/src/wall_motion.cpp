#include "demLib/wall_motion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include <Eigen/Geometry>

#include "demLib/error.hpp"

namespace dem {

namespace {

std::string describe(const Vec3& v) {
    std::ostringstream s;
    s << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
    return s.str();
}

void requireValidInterval(const char* keyword, double tStart, double tEnd) {
    if (!std::isfinite(tStart) || !std::isfinite(tEnd)) {
        std::ostringstream s;
        s << "wall motion '" << keyword << "': tStart = " << tStart << ", tEnd = " << tEnd
          << "; expected finite times";
        throw InputError(s.str());
    }
    if (!(tEnd > tStart)) {
        std::ostringstream s;
        s << "wall motion '" << keyword << "': tEnd = " << tEnd << " is not after tStart = " << tStart
          << "; expected tEnd > tStart";
        throw InputError(s.str());
    }
}

}  // namespace

RigidTransform MotionSegment::displacement(double duration) const {
    RigidTransform move;
    if (kind == Kind::Translate) {
        move.translation = velocity * duration;
    } else {
        // Rotation about a fixed axis through axisPoint: x -> a + R (x - a).
        move.rotation = Eigen::AngleAxisd(angularVelocity * duration, axisDirection).toRotationMatrix();
        move.translation = axisPoint - move.rotation * axisPoint;
    }
    return move;
}

void WallMotion::addTranslation(double tStart, double tEnd, const Vec3& velocity) {
    requireValidInterval("translate", tStart, tEnd);
    if (!velocity.allFinite()) {
        throw InputError("wall motion 'translate': velocity " + describe(velocity) +
                         " is not finite; expected a finite vector in m/s");
    }
    MotionSegment segment;
    segment.kind = MotionSegment::Kind::Translate;
    segment.tStart = tStart;
    segment.tEnd = tEnd;
    segment.velocity = velocity;
    append(segment);
}

void WallMotion::addRotation(double tStart, double tEnd, const Vec3& axisPoint, const Vec3& axisDirection,
                             double angularVelocity) {
    requireValidInterval("rotate", tStart, tEnd);
    if (!axisPoint.allFinite() || !axisDirection.allFinite() || !std::isfinite(angularVelocity)) {
        throw InputError("wall motion 'rotate': axis point " + describe(axisPoint) + ", axis direction " +
                         describe(axisDirection) + " or angular velocity is not finite; expected finite values");
    }
    const double length = axisDirection.norm();
    if (!(length > 0.0)) {
        throw InputError("wall motion 'rotate': axis direction " + describe(axisDirection) +
                         " is zero; expected a non-zero vector");
    }
    MotionSegment segment;
    segment.kind = MotionSegment::Kind::Rotate;
    segment.tStart = tStart;
    segment.tEnd = tEnd;
    segment.axisPoint = axisPoint;
    segment.axisDirection = axisDirection / length;
    segment.angularVelocity = angularVelocity;
    append(segment);
}

bool WallMotion::overlapsLoad(double tStart, double tEnd) const {
    return hasLoad_ && tStart < load_.tEnd() && load_.tStart < tEnd;
}

void WallMotion::addLoad(const WallLoad& load) {
    if (hasLoad_) throw InputError("wall motion 'load': the wall has a load already; expected at most one");
    requireValidInterval("load", load.tStart, load.tRaise);
    if (!load.direction.allFinite() || !(load.direction.norm() > 0.0))
        throw InputError("wall motion 'load': direction " + describe(load.direction) +
                         " is zero or not finite; expected a non-zero vector (the way the wall is lowered)");
    auto requirePositive = [](const char* what, double value, const char* unit) {
        if (!(value > 0.0) || !std::isfinite(value)) {
            std::ostringstream s;
            s << "wall motion 'load': " << what << " = " << value << "; expected a positive number of " << unit;
            throw InputError(s.str());
        }
    };
    requirePositive("mass", load.mass, "kg");
    requirePositive("speed", load.speed, "m/s");
    requirePositive("stroke", load.stroke, "m");
    WallLoad checked = load;
    checked.direction = load.direction / load.direction.norm();
    for (const MotionSegment& segment : segments_)
        if (segment.tStart < checked.tEnd() && checked.tStart < segment.tEnd) {
            std::ostringstream s;
            s << "wall motion 'load': its window " << checked.tStart << "-" << checked.tEnd()
              << " s (lowered from tStart, raised from tRaise, back after stroke/speed) overlaps the segment "
              << segment.tStart << "-" << segment.tEnd << " s; expected a load apart from the segments";
            throw InputError(s.str());
        }
    load_ = checked;
    hasLoad_ = true;
    loadState_ = {};
}

void WallMotion::advanceLoad(double t, double dt, double forceAlong, double gravityAlong) {
    if (!hasLoad_) return;
    WallLoadState& s = loadState_;
    if (t < load_.tStart || t >= load_.tEnd()) {
        s = {};
        return;
    }
    if (t < load_.tRaise) {
        // Symplectic Euler (the force is this step's); the hoist holds it back
        // beyond `speed`, the stop at `stroke`, and it rises no higher than it started.
        s.velocity = std::min(s.velocity + dt * (gravityAlong + forceAlong / load_.mass), load_.speed);
        s.offset += dt * s.velocity;
        if (s.offset > load_.stroke) {
            s.offset = load_.stroke;
            s.velocity = std::min(s.velocity, 0.0);
        } else if (s.offset < 0.0) {
            s.offset = 0.0;
            s.velocity = std::max(s.velocity, 0.0);
        }
        return;
    }
    s.velocity = -load_.speed;
    s.offset += dt * s.velocity;
    if (s.offset <= 0.0) s = {};
}

void WallMotion::append(const MotionSegment& segment) {
    if (overlapsLoad(segment.tStart, segment.tEnd)) {
        std::ostringstream s;
        s << "wall motion: segment " << segment.tStart << "-" << segment.tEnd << " s overlaps the load's window "
          << load_.tStart << "-" << load_.tEnd() << " s; expected segments apart from the load";
        throw InputError(s.str());
    }
    if (!segments_.empty() && segment.tStart < segments_.back().tEnd) {
        std::ostringstream s;
        s << "wall motion: segment starting at t = " << segment.tStart
          << " overlaps the previous segment, which ends at t = " << segments_.back().tEnd
          << "; expected segments in time order without overlap";
        throw InputError(s.str());
    }
    const RigidTransform before = poseAfter_.empty() ? RigidTransform{} : poseAfter_.back();
    segments_.push_back(segment);
    poseAfter_.push_back(before.followedBy(segment.displacement(segment.tEnd - segment.tStart)));
}

void WallMotion::setRemovalTime(double t) {
    if (std::isnan(t)) {
        throw InputError("wall motion 'removeAt': time is NaN; expected a number");
    }
    removalTime_ = t;
}

RigidTransform WallMotion::at(double t) const {
    RigidTransform pose = prescribedAt(t);
    if (hasLoad_) pose.translation += loadState_.offset * load_.direction;
    return pose;
}

RigidTransform WallMotion::prescribedAt(double t) const {
    // Segments are few (a handful per wall): a linear scan is cheapest.
    RigidTransform pose;
    for (std::size_t i = 0; i < segments_.size(); ++i) {
        const MotionSegment& segment = segments_[i];
        if (t < segment.tStart) {
            break;
        }
        if (t < segment.tEnd) {
            return pose.followedBy(segment.displacement(t - segment.tStart));
        }
        pose = poseAfter_[i];
    }
    return pose;
}

bool WallMotion::isMovingAt(double t) const {
    if (hasLoad_ && load_.tStart <= t && t < load_.tEnd()) return true;
    for (const MotionSegment& segment : segments_)
        if (segment.tStart <= t && t < segment.tEnd) return true;
    return false;
}

double WallMotion::nextChangeAfter(double t) const {
    double next = std::numeric_limits<double>::infinity();
    for (const MotionSegment& segment : segments_) {
        if (t < segment.tStart) {
            next = segment.tStart;
            break;
        }
        if (t < segment.tEnd) {
            next = segment.tEnd;
            break;
        }
    }
    if (hasLoad_) {
        if (t < load_.tStart) next = std::min(next, load_.tStart);
        else if (t < load_.tEnd()) next = std::min(next, load_.tEnd());
    }
    return next;
}

Vec3 WallMotion::velocityAt(const Vec3& worldPoint, double t) const {
    const Vec3 loaded = hasLoad_ ? Vec3(loadState_.velocity * load_.direction) : Vec3(Vec3::Zero());
    return loaded + prescribedVelocityAt(worldPoint, t);
}

Vec3 WallMotion::prescribedVelocityAt(const Vec3& worldPoint, double t) const {
    for (const MotionSegment& segment : segments_) {
        if (t < segment.tStart) {
            break;
        }
        if (t < segment.tEnd) {
            if (segment.kind == MotionSegment::Kind::Translate) {
                return segment.velocity;
            }
            return (segment.angularVelocity * segment.axisDirection).cross(worldPoint - segment.axisPoint);
        }
    }
    return Vec3::Zero();
}

}  // namespace dem
