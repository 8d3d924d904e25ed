// HandDeviceModel: the haptic device's handle (a mass with Coulomb friction) gripped by the
// operator's arm (a mass-spring-damper pulling towards where the hand means to go), driven by the
// force the controller renders through a transport delay and a zero-order hold, with the work that
// rendered force does counted for a passivity observer.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <Eigen/Core>

#include "hal/clock.hpp"

namespace stencil::sim {

// The operator's arm as seen at the handle: its mass moves with the handle, and it pulls the handle
// towards the intended point with F_hand = k (x_intent - x) + b (v_intent - v).
struct HandParameters {
  std::string_view name;             // for tables: "relaxed", "medium", "stiff", "none"
  double mass_kg = 0.0;              // added to the device's mass
  double stiffness_n_per_m = 0.0;    // k
  double damping_n_s_per_m = 0.0;    // b
};

// Presets for a light, an ordinary and a firm grasp (the figures issue 29 asks for).
inline constexpr HandParameters kRelaxedHand{"relaxed", 0.1, 50.0, 1.0};
inline constexpr HandParameters kMediumHand{"medium", 0.3, 300.0, 5.0};
inline constexpr HandParameters kStiffHand{"stiff", 0.5, 1000.0, 15.0};
// No hand on the handle: the device's mass alone, nothing pulling it.
inline constexpr HandParameters kNoHand{"none", 0.0, 0.0, 0.0};
// The three grasps in order of stiffness, for a table over them.
inline constexpr std::array<HandParameters, 3> kHandPresets{kRelaxedHand, kMediumHand, kStiffHand};

[[nodiscard]] constexpr HandParameters relaxed_hand() { return kRelaxedHand; }
[[nodiscard]] constexpr HandParameters medium_hand() { return kMediumHand; }
[[nodiscard]] constexpr HandParameters stiff_hand() { return kStiffHand; }

inline constexpr double kMinimumSubstepRateHz = 10'000.0;
inline constexpr double kDefaultSubstepRateHz = 20'000.0;

// The device itself and its link. Masses must be positive (device) and not negative (hand): the
// model divides by their sum.
struct DeviceParameters {
  double mass_kg = 0.2;                        // the handle's effective mass
  double coulomb_friction_n = 0.05;            // static and sliding alike (no stiction peak)
  double viscous_damping_n_s_per_m = 0.0;      // physical damping in the mechanism, if any
  double transport_delay_s = 0.0;              // command to motor: 0 direct, more over PIO or CAN;
                                               // negative is taken as 0
  double substep_rate_hz = kDefaultSubstepRateHz;  // below kMinimumSubstepRateHz is raised to it
};

enum class ForceCommandStatus : std::uint8_t {
  Queued,      // will take effect at commanded time + transport delay (at once when that has passed)
  QueueFull,   // refused: kForceQueueCapacity commands still waiting; the device goes on as before
  OutOfOrder,  // refused: commanded earlier than the previous accepted command
  NotFinite,   // refused: a NaN or infinite component
};

class HandDeviceModel {
 public:
  // Commands waiting out the transport delay: room for a 63 ms delay at 1 kHz, well beyond the few
  // milliseconds a link is expected to add (an assumption; the rigs' delays are not measured yet).
  // When it is full the newest command is refused and counted (refused_commands()), so the queue
  // never grows and the force already waiting still arrives in order.
  static constexpr std::size_t kForceQueueCapacity = 64;

  // The handle at rest at `start_mm` (device mm) at `start_ns`, the hand intending to stay there,
  // no force applied. A sub-step rate below kMinimumSubstepRateHz (or not a number) is raised to
  // kMinimumSubstepRateHz rather than refused: substep_rate_hz() says what was used. The rate is
  // rounded to a whole number of nanoseconds per sub-step.
  HandDeviceModel(const DeviceParameters& device, const HandParameters& hand, hal::MonotonicNs start_ns,
                  const Eigen::Vector3d& start_mm);

  // Where the hand means the handle to be from now on: `intent_mm` now, moving on at
  // `intent_velocity_mm_per_s` (device space) until the next call.
  void set_intent(const Eigen::Vector3d& intent_mm, const Eigen::Vector3d& intent_velocity_mm_per_s);

  // The controller's force for the cycle at `commanded_ns` (N). The device applies it from
  // commanded_ns + transport delay and holds it until the next command takes over.
  [[nodiscard]] ForceCommandStatus command_force(hal::MonotonicNs commanded_ns, const Eigen::Vector3d& force_n);

  // Integrates up to `t_ns` in sub-steps on a fixed grid from the start time, a step cut short
  // where a command takes effect and at t_ns: a caller whose times fall on the grid (each 1 ms at
  // 20 or 10 kHz) gets the same result however often it calls. An earlier time than now_ns() does
  // nothing: time never goes back.
  void advance_to(hal::MonotonicNs t_ns);

  [[nodiscard]] hal::MonotonicNs now_ns() const { return now_ns_; }
  [[nodiscard]] Eigen::Vector3d position_mm() const { return 1000.0 * position_m_; }
  [[nodiscard]] Eigen::Vector3d velocity_mm_per_s() const { return 1000.0 * velocity_m_per_s_; }
  // The force the motors drive now (N): the last command to take effect, zero before the first.
  [[nodiscard]] const Eigen::Vector3d& applied_force_n() const { return applied_force_n_; }
  // The arm's pull on the handle now (N).
  [[nodiscard]] Eigen::Vector3d hand_force_n() const;
  // Work done by the applied (rendered) force on the handle since construction or the last reset
  // (J): the sum over sub-steps of F . dx. Positive: the device put energy into the hand and handle.
  [[nodiscard]] double rendered_work_j() const { return rendered_work_j_; }
  void reset_rendered_work() { rendered_work_j_ = 0.0; }

  [[nodiscard]] double substep_rate_hz() const { return 1e9 / static_cast<double>(substep_ns_); }
  [[nodiscard]] std::size_t pending_commands() const { return queue_count_; }
  [[nodiscard]] std::uint64_t refused_commands() const { return refused_commands_; }
  [[nodiscard]] const DeviceParameters& device() const { return device_; }
  [[nodiscard]] const HandParameters& hand() const { return hand_; }

 private:
  struct PendingForce {
    hal::MonotonicNs effect_ns = 0;
    Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  };

  void apply_due_commands();
  void substep(double dt_s);
  [[nodiscard]] Eigen::Vector3d intent_m_at(hal::MonotonicNs t_ns) const;

  DeviceParameters device_;
  HandParameters hand_;
  hal::MonotonicNs start_ns_;
  hal::MonotonicNs now_ns_;
  hal::MonotonicNs substep_ns_;
  hal::MonotonicNs delay_ns_;

  Eigen::Vector3d position_m_;
  Eigen::Vector3d velocity_m_per_s_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d intent_m_;
  Eigen::Vector3d intent_velocity_m_per_s_ = Eigen::Vector3d::Zero();
  hal::MonotonicNs intent_set_ns_;
  Eigen::Vector3d applied_force_n_ = Eigen::Vector3d::Zero();
  double rendered_work_j_ = 0.0;

  // A ring of commands in the order they take effect.
  std::array<PendingForce, kForceQueueCapacity> queue_{};
  std::size_t queue_head_ = 0;
  std::size_t queue_count_ = 0;
  hal::MonotonicNs last_commanded_ns_;
  bool have_command_ = false;
  std::uint64_t refused_commands_ = 0;
};

}  // namespace stencil::sim
