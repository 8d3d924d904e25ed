// HandDeviceModel: the handle and the arm integrated with semi-implicit Euler, implicit in the
// damping and in the Coulomb friction (so sticking and slipping are decided exactly per sub-step).
#include "sim/operator/hand_device_model.hpp"

#include <algorithm>
#include <cmath>

namespace stencil::sim {

namespace {

constexpr double kMetresPerMillimetre = 1e-3;
constexpr double kSecondsPerNanosecond = 1e-9;

hal::MonotonicNs substep_period_ns(double rate_hz) {
  // NaN fails every comparison, so it is raised too.
  const double rate = rate_hz >= kMinimumSubstepRateHz ? rate_hz : kMinimumSubstepRateHz;
  return std::max<hal::MonotonicNs>(1, std::llround(1e9 / rate));
}

}  // namespace

HandDeviceModel::HandDeviceModel(const DeviceParameters& device, const HandParameters& hand,
                                 hal::MonotonicNs start_ns, const Eigen::Vector3d& start_mm)
    : device_(device),
      hand_(hand),
      start_ns_(start_ns),
      now_ns_(start_ns),
      substep_ns_(substep_period_ns(device.substep_rate_hz)),
      delay_ns_(std::max<hal::MonotonicNs>(0, std::llround(device.transport_delay_s * 1e9))),
      position_m_(kMetresPerMillimetre * start_mm),
      intent_m_(kMetresPerMillimetre * start_mm),
      intent_set_ns_(start_ns),
      last_commanded_ns_(start_ns) {}

void HandDeviceModel::set_intent(const Eigen::Vector3d& intent_mm, const Eigen::Vector3d& intent_velocity_mm_per_s) {
  intent_m_ = kMetresPerMillimetre * intent_mm;
  intent_velocity_m_per_s_ = kMetresPerMillimetre * intent_velocity_mm_per_s;
  intent_set_ns_ = now_ns_;
}

ForceCommandStatus HandDeviceModel::command_force(hal::MonotonicNs commanded_ns, const Eigen::Vector3d& force_n) {
  ForceCommandStatus status = ForceCommandStatus::Queued;
  if (!force_n.allFinite()) {
    status = ForceCommandStatus::NotFinite;
  } else if (have_command_ && commanded_ns < last_commanded_ns_) {
    status = ForceCommandStatus::OutOfOrder;
  } else if (queue_count_ == kForceQueueCapacity) {
    status = ForceCommandStatus::QueueFull;
  }
  if (status != ForceCommandStatus::Queued) {
    ++refused_commands_;
    return status;
  }
  have_command_ = true;
  last_commanded_ns_ = commanded_ns;
  queue_[(queue_head_ + queue_count_) % kForceQueueCapacity] = PendingForce{commanded_ns + delay_ns_, force_n};
  ++queue_count_;
  // Already due (no delay, or the model has run past it): the motors take it now.
  apply_due_commands();
  return status;
}

void HandDeviceModel::apply_due_commands() {
  while (queue_count_ > 0 && queue_[queue_head_].effect_ns <= now_ns_) {
    applied_force_n_ = queue_[queue_head_].force_n;
    queue_head_ = (queue_head_ + 1) % kForceQueueCapacity;
    --queue_count_;
  }
}

void HandDeviceModel::advance_to(hal::MonotonicNs t_ns) {
  while (now_ns_ < t_ns) {
    apply_due_commands();
    // The next point of the sub-step grid, or sooner where a held force changes or the caller reads.
    hal::MonotonicNs next_ns = start_ns_ + ((now_ns_ - start_ns_) / substep_ns_ + 1) * substep_ns_;
    next_ns = std::min(next_ns, t_ns);
    if (queue_count_ > 0) next_ns = std::min(next_ns, queue_[queue_head_].effect_ns);
    substep(kSecondsPerNanosecond * static_cast<double>(next_ns - now_ns_));
    now_ns_ = next_ns;
  }
  apply_due_commands();
}

Eigen::Vector3d HandDeviceModel::intent_m_at(hal::MonotonicNs t_ns) const {
  return intent_m_ + kSecondsPerNanosecond * static_cast<double>(t_ns - intent_set_ns_) * intent_velocity_m_per_s_;
}

Eigen::Vector3d HandDeviceModel::hand_force_n() const {
  return hand_.stiffness_n_per_m * (intent_m_at(now_ns_) - position_m_) +
         hand_.damping_n_s_per_m * (intent_velocity_m_per_s_ - velocity_m_per_s_);
}

void HandDeviceModel::substep(double dt_s) {
  // M (v' - v) = dt (F - D v' - mu v'/|v'|), where F is what is known at the start of the step
  // (the held force, the arm's spring, the arm's damping towards the intended velocity) and the
  // damping D (arm and mechanism) and the friction mu act on the end-of-step velocity v'. Implicit
  // damping is stable for any D; implicit friction stops the handle exactly instead of reversing it
  // or chattering about zero, and a resting handle stays put while |F| <= mu.
  const double mass_kg = device_.mass_kg + hand_.mass_kg;
  const double damping_n_s_per_m = hand_.damping_n_s_per_m + device_.viscous_damping_n_s_per_m;
  const Eigen::Vector3d known_force_n = applied_force_n_ +
                                        hand_.stiffness_n_per_m * (intent_m_at(now_ns_) - position_m_) +
                                        hand_.damping_n_s_per_m * intent_velocity_m_per_s_;
  const double effective_mass_kg = mass_kg + dt_s * damping_n_s_per_m;
  const Eigen::Vector3d free_velocity = (mass_kg * velocity_m_per_s_ + dt_s * known_force_n) / effective_mass_kg;
  // The most the friction can change the velocity in this step (m/s). v' is parallel to the
  // frictionless v, shortened by this, or zero when it would not reach past zero.
  const double friction_velocity = dt_s * device_.coulomb_friction_n / effective_mass_kg;
  const double free_speed = free_velocity.norm();
  if (free_speed <= friction_velocity) {
    velocity_m_per_s_.setZero();
  } else {
    velocity_m_per_s_ = (1.0 - friction_velocity / free_speed) * free_velocity;
  }
  // Semi-implicit: the new velocity moves the handle, and the held force does its work over that
  // displacement (exact for a force held constant over the step).
  const Eigen::Vector3d displacement_m = dt_s * velocity_m_per_s_;
  position_m_ += displacement_m;
  rendered_work_j_ += applied_force_n_.dot(displacement_m);
}

}  // namespace stencil::sim
