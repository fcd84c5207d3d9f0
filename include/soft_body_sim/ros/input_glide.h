// Smooth streamed inputs: the commanded pose of an anchor, a target or a holder on a tf frame between its
// stamped inputs.
//
// A pose streamed at 20 Hz and reached within one step leaves the anchor jumping 2 cm in 5 ms and resting
// 45 ms. Here each input is reached at the speed its stamp implies: the distance from the previous input
// over the time since the previous input's stamp. The pose moves from where the glide was at the new
// input's stamp to the input, linearly in position and by slerp in orientation, arriving about one
// interval after the stamp: a stream's path at the stream's speed, one interval behind it. (Reaching each
// input one interval after its stamp instead would move faster than the stream wherever a short interval
// follows a long one: the glide not yet done when the next input comes, at 1.6 times the speed of the
// demo's circle under a loaded publisher's jitter.) Only stamps decide: a replay of the same inputs glides
// the same, bit for bit.
// - The first input of a source, and one stamped as its previous, is reached at once (in the step its
//   stamp falls in): there is no interval to spread it over.
// - When inputs stop, the glide ends at the last one and holds it. After a pause longer than
//   `max_interval`, the next input is reached over max_interval, not the pause; no glide takes longer
//   (one far behind its stream catches up faster), and an input that only turns takes its interval.
// - A late input (stamped before the step it reaches) starts its glide at its stamp, as if on time: the
//   step it reaches puts the anchor where the glide is by then.
// - A tf frame is its own stream (`follow`): where tf has transforms on both sides of a step's end (the
//   frame is published ahead), tf's interpolation there is exact and smooth; past the frame's newest
//   transform (late), each newer one glides in from the step that first sees it, rather than being
//   reached in that step, and the holder stays a glide until it rests on tf's pose. When a late
//   transform is seen depends on when it came: a replay is exact only for frames published ahead.
// - A target after a pause longer than `max_interval` starts afresh, at once (`addAfterPauseAtOnce`).
// Plain data: unit-testable without a master.
#pragma once

#include <algorithm>
#include <optional>

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
class InputGlide
{
public:
  /// An input stamped `t` [s of simulated time] toward `position` [m] and, if given, `orientation`.
  void add(double t, const Vec3& position, const std::optional<Eigen::Quaterniond>& orientation, double max_interval)
  {
    addSeenAt(t, t, position, orientation, max_interval);
  }

  /// An input stamped `stamp` but seen only at `start` [s], after its stamp (a tf frame's newest
  /// transform, when the frame is published late): it glides from where the glide is at `start`, at the
  /// stream's speed, so it arrives about one interval after `start`. Not for replays: when a late
  /// input is seen depends on when it came.
  void addSeenAt(double stamp, double start, const Vec3& position, const std::optional<Eigen::Quaterniond>& orientation,
                 double max_interval)
  {
    const double interval = started_ ? std::min(stamp - last_stamp_, max_interval) : 0.0;
    double duration = 0.0;
    if (interval > 0.0)
    {
      from_ = positionAt(start);
      from_orientation_ = orientation && to_orientation_ ? orientationAt(start) : orientation;
      const double speed = (position - to_).norm() / interval;  // the stream's, from the previous input
      const double distance = (position - from_).norm();
      duration = speed > 0.0 ? std::min(distance / speed, max_interval) : interval;
    }
    else
    {
      from_ = position;
      from_orientation_ = orientation;
    }
    to_ = position;
    to_orientation_ = orientation;
    from_time_ = start;
    to_time_ = start + duration;
    last_stamp_ = stamp;
    started_ = true;
  }

  /// The pose is known exactly at time t (a tf frame's transform interpolated there): it is there, at
  /// rest, and counts as an input stamped t for the speed of the next.
  void place(double t, const Vec3& position, const std::optional<Eigen::Quaterniond>& orientation)
  {
    from_ = to_ = position;
    from_orientation_ = to_orientation_ = orientation;
    from_time_ = to_time_ = last_stamp_ = t;
    started_ = true;
  }

  /// One step, from `start` to `end` [s], of a holder on a tf frame, given the frame's pose from tf: its pose
  /// at `end` where `newest` is nullopt (tf had transforms on both sides of `end`), else its newest
  /// transform, stamped `newest` (the frame is late). positionAt(end) and orientationAt(end) are then the
  /// holder's: where the newest transform glides in from the step that first saw it, or tf's exact pose.
  /// Once it has glided, tf's poses glide in too, each stamped its step's end, until the holder comes to
  /// rest on tf's pose (the frame stopped): a frame stamped about when its steps end is late for one step
  /// and not for the next, and a holder put on tf's pose there would jump the interval it is behind.
  void follow(double start, double end, const Vec3& position, const Eigen::Quaterniond& orientation,
              const std::optional<double>& newest, double max_interval)
  {
    if (newest)
    {
      if (!started_ || *newest > last_stamp_)
        addSeenAt(*newest, start, position, orientation, max_interval);
      on_frame_ = false;
      return;
    }
    const bool same = to_ == position && to_orientation_ && to_orientation_->coeffs() == orientation.coeffs();
    if (!started_ || on_frame_ || (same && !movingAfter(start)))
    {
      place(end, position, orientation);
      on_frame_ = true;
    }
    else if (!same)  // a frame at rest adds nothing: the glide ends on it at the speed it had
      addSeenAt(end, start, position, orientation, max_interval);
  }

  /// As add, except that an input after a pause longer than `max_interval` starts a new stream, reached
  /// at once: a target's, which the body's own dynamics approach.
  void addAfterPauseAtOnce(double t, const Vec3& position, double max_interval)
  {
    if (started_ && t - last_stamp_ > max_interval)
      started_ = false;
    add(t, position, std::nullopt, max_interval);
  }

  /// The commanded position [m] at time t [s]: exactly the input's once the glide has ended.
  Vec3 positionAt(double t) const
  {
    const double s = share(t);
    return s < 1.0 ? Vec3(from_ + s * (to_ - from_)) : to_;
  }
  /// The commanded orientation at time t, if the inputs give one.
  std::optional<Eigen::Quaterniond> orientationAt(double t) const
  {
    if (!to_orientation_)
      return std::nullopt;
    const double s = share(t);
    return from_orientation_ && s < 1.0 ? from_orientation_->slerp(s, *to_orientation_) : *to_orientation_;
  }

  /// True while the commanded pose still changes after time t [s].
  bool movingAfter(double t) const { return started_ && t < to_time_; }

private:
  /// How far along the glide is at time t, from 0 to 1.
  double share(double t) const
  {
    return to_time_ > from_time_ ? std::clamp((t - from_time_) / (to_time_ - from_time_), 0.0, 1.0) : 1.0;
  }

  bool started_ = false;
  bool on_frame_ = false;  ///< follow: placed on tf's exact pose in the last step
  double last_stamp_ = 0.0;  ///< [s] of the last input
  double from_time_ = 0.0, to_time_ = 0.0;  ///< [s]
  Vec3 from_ = Vec3::Zero(), to_ = Vec3::Zero();  ///< [m]
  std::optional<Eigen::Quaterniond> from_orientation_, to_orientation_;
};

}  // namespace soft_body_sim
