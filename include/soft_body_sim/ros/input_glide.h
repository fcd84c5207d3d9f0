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
// - A tf frame is its own stream (onFrame, followNewest): where tf has transforms on both sides of a step's
//   end (the frame is published ahead), tf's interpolation there is exact and smooth; past the frame's
//   newest transform (late), each newer transform glides in from the step that first sees it, rather than
//   being reached in that step, and the holder glides on the frame's transforms until it rests on tf's
//   pose. When a late transform is seen depends on when it came: a replay is exact only for frames
//   published ahead.
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
    glide(t, t, position, orientation, max_interval, 1.0);
  }

  /// A holder on a tf frame, in a step ending at `end` [s] where tf has the frame on both sides (published
  /// ahead): it takes tf's pose there if it is on the frame (it was in the last step, it has not started,
  /// or its glide ended right there, the frame at rest), and says so. Otherwise it keeps gliding
  /// (followNewest): a frame stamped about when its steps end is late for one step and not for the next,
  /// and a holder put back on tf's pose would jump the interval it is behind.
  bool onFrame(double end, const Vec3& position, const Eigen::Quaterniond& orientation)
  {
    if (!started_ || on_frame_ || (!movingAfter(end) && isLastInput(position, orientation)))
    {
      place(end, position, orientation);
      on_frame_ = true;
    }
    return on_frame_;
  }

  /// A holder on a tf frame, in a step from `start` [s] that ends past the frame's newest transform (the
  /// frame is late) or in which it is off the frame: a newest transform newer than the last glides in from
  /// `start`, at the frame's speed, faster (kFrameCatchUp) while the holder is more than an interval behind.
  void followNewest(double start, double stamp, const Vec3& position, const Eigen::Quaterniond& orientation,
                    double max_interval)
  {
    on_frame_ = false;
    if (!started_ || (stamp > last_stamp_ && !isLastInput(position, orientation)))
      glide(stamp, start, position, orientation, max_interval, kFrameCatchUp);
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
  /// The pose is known exactly at time t (a tf frame's transform interpolated there): it is there, at
  /// rest, and counts as an input stamped t for the speed of the next.
  void place(double t, const Vec3& position, const std::optional<Eigen::Quaterniond>& orientation)
  {
    from_ = to_ = position;
    from_orientation_ = to_orientation_ = orientation;
    from_time_ = to_time_ = last_stamp_ = t;
    started_ = true;
  }

  bool isLastInput(const Vec3& position, const Eigen::Quaterniond& orientation) const
  {
    return to_ == position && to_orientation_ && to_orientation_->coeffs() == orientation.coeffs();
  }

  /// How much faster than its frame a holder may glide while it is more than one interval behind: a lag
  /// (a tick that saw a transform late, dropped time, a frame that jumped) shrinks instead of lasting
  /// as long as the frame moves, and the holder never runs at more than this times the frame's speed.
  static constexpr double kFrameCatchUp = 1.25;

  /// An input stamped `stamp`, taken from `start` [s] (its stamp, or after it: a tf frame's transform seen
  /// in a later step), from where the glide is then, at the stream's speed (the distance from the
  /// previous input over the time between their stamps); while it would take longer than that interval,
  /// at up to `catch_up` times that speed. A late input's start depends on when it came: not for replays.
  void glide(double stamp, double start, const Vec3& position, const std::optional<Eigen::Quaterniond>& orientation,
             double max_interval, double catch_up)
  {
    const double interval = started_ ? std::min(stamp - last_stamp_, max_interval) : 0.0;
    double duration = 0.0;
    if (interval > 0.0)
    {
      from_ = positionAt(start);
      from_orientation_ = orientation && to_orientation_ ? orientationAt(start) : orientation;
      const double speed = (position - to_).norm() / interval;  // the stream's, from the previous input
      const double distance = (position - from_).norm();
      const double at_speed = distance / speed;
      // An input that only turns takes its interval, or what is left of the glide under way if longer (a
      // late transform seen just after the pose tf gave for the step before: no jump for it).
      duration = speed > 0.0 ? std::min(at_speed <= interval ? at_speed : std::max(interval, at_speed / catch_up),
                                        max_interval) :
                               std::max(interval, to_time_ - start);
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

  /// How far along the glide is at time t, from 0 to 1.
  double share(double t) const
  {
    return to_time_ > from_time_ ? std::clamp((t - from_time_) / (to_time_ - from_time_), 0.0, 1.0) : 1.0;
  }

  bool started_ = false;
  bool on_frame_ = false;  ///< onFrame: on tf's exact pose in the last step
  double last_stamp_ = 0.0;  ///< [s] of the last input
  double from_time_ = 0.0, to_time_ = 0.0;  ///< [s]
  Vec3 from_ = Vec3::Zero(), to_ = Vec3::Zero();  ///< [m]
  std::optional<Eigen::Quaterniond> from_orientation_, to_orientation_;
};

}  // namespace soft_body_sim
