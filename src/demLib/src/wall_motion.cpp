#include "demLib/wall_motion.hpp"

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

void WallMotion::append(const MotionSegment& segment) {
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
    for (const MotionSegment& segment : segments_)
        if (segment.tStart <= t && t < segment.tEnd) return true;
    return false;
}

double WallMotion::nextChangeAfter(double t) const {
    for (const MotionSegment& segment : segments_) {
        if (t < segment.tStart) return segment.tStart;
        if (t < segment.tEnd) return segment.tEnd;
    }
    return std::numeric_limits<double>::infinity();
}

Vec3 WallMotion::velocityAt(const Vec3& worldPoint, double t) const {
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
