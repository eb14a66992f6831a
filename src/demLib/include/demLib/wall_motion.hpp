#pragma once
// Prescribed rigid motion of a wall: a sequence of non-overlapping segments,
// each active on [tStart, tEnd), that either translate the wall with a constant
// velocity or rotate it with a constant angular velocity about an axis fixed in
// the world frame.  Between and after segments the wall rests where the last
// finished segment left it.  Poses are evaluated in closed form from the segment
// list (never by summing per-step increments), so a restarted run at time t
// sees exactly the same wall as an uninterrupted one.
//
// Reference frame: the wall's geometry is given at t = -infinity (before every
// segment); x_world = R(t) x_ref + c(t).
//
// One exception to the closed form: a load (WallLoad), a wall lowered onto what
// lies below it and left to rest there under its own weight, whose position
// follows the forces on it.  Its offset along the load's direction is state
// (WallLoadState), advanced by the simulation each step and kept in restart
// files; outside the load's window it is zero.
#include <limits>
#include <vector>

#include "demLib/vec3.hpp"

namespace dem {

struct RigidTransform {
    Mat3 rotation = Mat3::Identity();
    Vec3 translation = Vec3::Zero();

    Vec3 apply(const Vec3& referencePoint) const { return rotation * referencePoint + translation; }
    Vec3 applyToDirection(const Vec3& referenceDirection) const { return rotation * referenceDirection; }
    Vec3 applyInverse(const Vec3& worldPoint) const {
        return rotation.transpose() * (worldPoint - translation);
    }
    Vec3 applyInverseToDirection(const Vec3& worldDirection) const {
        return rotation.transpose() * worldDirection;
    }
    // (after ∘ this): first this transform, then `after`.
    RigidTransform followedBy(const RigidTransform& after) const {
        return {after.rotation * rotation, after.rotation * translation + after.translation};
    }
};

struct MotionSegment {
    enum class Kind { Translate, Rotate };
    Kind kind = Kind::Translate;
    double tStart = 0.0;
    double tEnd = 0.0;
    Vec3 velocity = Vec3::Zero();       // Translate: m/s
    Vec3 axisPoint = Vec3::Zero();      // Rotate: a point on the axis (world frame)
    Vec3 axisDirection = Vec3::UnitZ(); // Rotate: unit axis (world frame), right-hand rule
    double angularVelocity = 0.0;       // Rotate: rad/s

    // Pose change produced by `duration` seconds of this segment.
    RigidTransform displacement(double duration) const;
};

// A wall lowered onto the powder and left to rest on it under its weight (the
// paper's pre-compaction stamp, a stamp of given weight: Fig. 4c-d).  From
// tStart it hangs on a hoist that lowers it along `direction` no faster than
// `speed`: m du/dt = m g.d + F.d with u <= speed (F: the particles' force on the
// wall), so it comes down at `speed` until what it touches carries its weight.
// From tRaise it is drawn back at `speed` to where it started.  It never goes
// farther than `stroke` from there (a mechanical stop), so by tEnd() =
// tRaise + stroke / speed it is back.  docs/walls.md, "A wall under load".
struct WallLoad {
    double tStart = 0.0;
    double tRaise = 0.0;
    Vec3 direction = -Vec3::UnitZ();  // unit, the way it is lowered
    double mass = 0.0;                // kg
    double speed = 0.0;               // m/s
    double stroke = 0.0;              // m
    double tEnd() const { return tRaise + stroke / speed; }
};

// Where a loaded wall is: `offset` along the load's direction from where the
// load started [m], and its velocity along it [m/s].
struct WallLoadState {
    double offset = 0.0;
    double velocity = 0.0;
};

class WallMotion {
public:
    // A wall that never moves and is never removed.
    WallMotion() = default;

    // Appends a segment.  Segments must be added in time order and must not
    // overlap (tStart >= previous tEnd).  Throws InputError otherwise, or when
    // tEnd <= tStart, a value is not finite, or the rotation axis is zero.  The
    // axis direction need not be unit length; it is normalised.
    void addTranslation(double tStart, double tEnd, const Vec3& velocity);
    void addRotation(double tStart, double tEnd, const Vec3& axisPoint, const Vec3& axisDirection,
                     double angularVelocity);

    // Adds a load (at most one).  Throws InputError for a non-positive mass,
    // speed or stroke, tRaise <= tStart, a zero direction, non-finite values, or
    // a window [tStart, tEnd()) that overlaps a segment (segments added later are
    // checked too).  The direction is normalised.
    void addLoad(const WallLoad& load);
    bool hasLoad() const { return hasLoad_; }
    const WallLoad& load() const { return load_; }
    const WallLoadState& loadState() const { return loadState_; }
    void setLoadState(const WallLoadState& state) { loadState_ = state; }
    // One step of the load from time t (the forces of time t): `forceAlong` is
    // the particles' force on the wall along the load's direction [N],
    // `gravityAlong` the gravity along it [m/s^2].  Outside the window the
    // state is zero.
    void advanceLoad(double t, double dt, double forceAlong, double gravityAlong);

    // From time `t` on, the wall no longer exists (isActive(t) == false).
    void setRemovalTime(double t);
    double removalTime() const { return removalTime_; }
    bool isActive(double t) const { return t < removalTime_; }

    bool isStatic() const { return segments_.empty() && !hasLoad_; }
    // Whether a segment or the load is under way at t (tStart <= t < tEnd).
    bool isMovingAt(double t) const;
    // The first segment start or end after t (infinity when none): until then
    // the wall keeps moving, or keeps resting, as at t.
    double nextChangeAfter(double t) const;
    const std::vector<MotionSegment>& segments() const { return segments_; }

    // Pose at time t: x_world = R x_ref + c (with a load: plus its present
    // offset, which is zero outside its window).
    RigidTransform at(double t) const;
    // Velocity of the wall material that is at `worldPoint` at time t:
    // v for a translation, omega x (p - axisPoint) for a rotation, 0 at rest
    // (with a load: plus its present velocity).
    Vec3 velocityAt(const Vec3& worldPoint, double t) const;

private:
    void append(const MotionSegment& segment);
    bool overlapsLoad(double tStart, double tEnd) const;
    RigidTransform prescribedAt(double t) const;
    Vec3 prescribedVelocityAt(const Vec3& worldPoint, double t) const;

    std::vector<MotionSegment> segments_;
    // poseAfter_[i]: pose once segments 0..i have all finished.
    std::vector<RigidTransform> poseAfter_;
    double removalTime_ = std::numeric_limits<double>::infinity();
    bool hasLoad_ = false;
    WallLoad load_;
    WallLoadState loadState_;
};

}  // namespace dem
