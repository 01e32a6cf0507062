// Prescribed motions of a wall: its displacement d(t) from the position it was built at (translation only), a pure
// function of time, so that a checkpointed run resumes on the same path. A wall without one moves at the velocity a
// driver sets (BasicSimulation::set_wall_velocity: a servo-held lid, a shear frame), zero unless set.
#pragma once
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>
#include "kernel/types.hpp"

namespace demcal::kernel {

class WallMotion {
 public:
  virtual ~WallMotion() = default;
  /// Displacement from the built position at time t [m].
  virtual Vec3 displacement(double t) const = 0;
  /// Velocity at time t [m/s] (right-continuous: at a start, the velocity just after it). Contacts see it when forces
  /// are evaluated at an instant (after a state was set); over a step they see the mean velocity of the step.
  virtual Vec3 velocity(double t) const = 0;
  /// The law's kind and numbers, for the checkpoint's configuration check.
  virtual void append_numbers(std::vector<double>& c) const = 0;
};

/// The strongest shaking a case accepts: a peak acceleration A (2 pi f)^2 of 500 g [m/s^2]. The seed's largest
/// setting is 9.3 g (0.11 mm at 145 Hz), the cut-off search's default bracket ends at 71 g, and 0.11 mm at 1000 Hz
/// (the frequency limit) is 443 g; far above, the walls throw the grains about rather than vibrate a bed (2 mm at
/// 400 Hz, 1288 g, was searched for a cohesive arch and called one "arched"; 1 cm at 1000 Hz is 40,000 g).
inline constexpr double kMaxVibrationPeakAcceleration = 500 * 9.81;

/// The weakest shaking a case accepts: a peak acceleration of 1e-4 g. Below it the wall pushes a grain with less than
/// a ten-thousandth of its weight, far under the force scatter of a packed bed: 0.01 Hz or 1e-12 m shook nothing and
/// were reported as vibrated runs (probe 59b). The seed's amplitude, 0.11 mm, reaches it at 0.48 Hz.
inline constexpr double kMinVibrationPeakAcceleration = 1e-4 * 9.81;

/// Why shaking of amplitude A [m] and frequency f [Hz] (both > 0) is not a vibration a case simulates (its peak
/// acceleration A (2 pi f)^2 outside [kMinVibrationPeakAcceleration, kMaxVibrationPeakAcceleration]), or "":
/// "a peak acceleration of X g, below ...".
inline std::string vibration_peak_defect(double amplitude, double frequency) {
  const double peak = amplitude * std::pow(2 * M_PI * frequency, 2);
  if (peak >= kMinVibrationPeakAcceleration && peak <= kMaxVibrationPeakAcceleration) return "";
  const auto g = [](double a) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", a / 9.81);
    return std::string(text);
  };
  return "a peak acceleration of " + g(peak) + " g, " +
         (peak > kMaxVibrationPeakAcceleration
              ? "above the " + g(kMaxVibrationPeakAcceleration) +
                    " g a vibrated bed is checked for (the seed's largest: 9.3 g): it throws the grains about"
              : "below the " + g(kMinVibrationPeakAcceleration) +
                    " g a vibrated bed is checked for: it shakes nothing (the seed: 0.11 mm at up to 145 Hz)");
}

/// vibration_peak_defect with the frequency named: "at f Hz gives a peak acceleration of ...", or "".
inline std::string vibration_strength_defect(double amplitude, double frequency) {
  const std::string defect = vibration_peak_defect(amplitude, frequency);
  if (defect.empty()) return "";
  char hz[32];
  std::snprintf(hz, sizeof hz, "%g", frequency);
  return std::string("at ") + hz + " Hz gives " + defect;
}

/// d(t) = A sin(2 pi f (t - t0)) e for t >= t0, 0 before: a vibrator (the seed's eccentric vibrator on the bin).
class SinusoidalMotion final : public WallMotion {
 public:
  /// direction: any nonzero vector (normalised); amplitude A [m] >= 0; frequency f [Hz] >= 0; start t0 [s].
  SinusoidalMotion(const Vec3& direction, double amplitude, double frequency, double start)
      : amplitude_(amplitude), frequency_(frequency), start_(start) {
    if (!(direction.allFinite() && direction.norm() > 0))
      throw std::invalid_argument("vibration direction must be a finite nonzero vector");
    if (!(amplitude >= 0 && std::isfinite(amplitude)))
      throw std::invalid_argument("vibration amplitude must be finite and >= 0 m, got " + std::to_string(amplitude));
    if (!(frequency >= 0 && std::isfinite(frequency)))
      throw std::invalid_argument("vibration frequency must be finite and >= 0 Hz, got " + std::to_string(frequency));
    if (!std::isfinite(start)) throw std::invalid_argument("vibration start must be finite");
    direction_ = direction.normalized();
  }
  Vec3 displacement(double t) const override {
    if (t <= start_) return Vec3::Zero();
    return (amplitude_ * std::sin(2.0 * M_PI * frequency_ * (t - start_))) * direction_;
  }
  Vec3 velocity(double t) const override {
    if (t < start_) return Vec3::Zero();
    const double w = 2.0 * M_PI * frequency_;
    return (amplitude_ * w * std::cos(w * (t - start_))) * direction_;
  }
  void append_numbers(std::vector<double>& c) const override {
    c.insert(c.end(), {1.0, direction_.x(), direction_.y(), direction_.z(), amplitude_, frequency_, start_});
  }
  double amplitude() const { return amplitude_; }
  double frequency() const { return frequency_; }
  /// Peak acceleration A (2 pi f)^2 [m/s^2].
  double peak_acceleration() const { const double w = 2.0 * M_PI * frequency_; return amplitude_ * w * w; }

 private:
  Vec3 direction_;
  double amplitude_, frequency_, start_;
};

}  // namespace demcal::kernel
