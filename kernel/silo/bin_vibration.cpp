#include "kernel/silo/bin_vibration.hpp"
#include "kernel/silo/input_error.hpp"
#include "kernel/walls/wall_motion.hpp"  // kMaxVibrationPeakAcceleration

#include <cmath>
#include <stdexcept>

namespace demcal::kernel::silo {

namespace {

constexpr double pi = 3.14159265358979323846;

// A subnormal is no physical setting (a typo or a unit slip), and its arithmetic is slow and imprecise.
void refuse_subnormal(const char* field, double value) {
    if (std::fpclassify(value) == FP_SUBNORMAL)
        reject_setting(field, value, "a subnormal number (below 2.2e-308): give 0 or a normal value");
}

void check_range(const char* field, double value, double max, const char* unit) {
    if (!std::isfinite(value) || value < 0 || value > max)
        reject_setting(field, value, "must be a finite number in [0, " + setting_text(max) + "] " + unit);
    refuse_subnormal(field, value);
}

Vec3 axis_of(VibrationDirection d) { return d == VibrationDirection::z ? Vec3::UnitZ() : Vec3::UnitX(); }

}  // namespace

std::string to_string(VibrationDirection d) { return d == VibrationDirection::z ? "z" : "x"; }

std::string to_string(VibratingPart p) { return p == VibratingPart::hopper ? "hopper" : "bin"; }

std::optional<VibratingPart> vibrating_part_named(const std::string& name) {
    for (const VibratingPart p : {VibratingPart::bin, VibratingPart::hopper})
        if (name == to_string(p)) return p;
    return std::nullopt;
}

double BinVibration::peak_acceleration() const {
    const double w = 2 * pi * frequency;
    return amplitude * w * w;
}

double BinVibration::peak_velocity() const { return amplitude * 2 * pi * frequency; }

void validate(const BinVibration& v) {
    check_range("vibration_frequency", v.frequency, 1000, "Hz");
    check_range("vibration_amplitude", v.amplitude, 0.01, "m");
    if (!std::isfinite(v.start_after_opening) || v.start_after_opening < 0)
        reject_setting("vibration_start", v.start_after_opening,
                       "must be a finite number of seconds >= 0 after the opening");
    refuse_subnormal("vibration_start", v.start_after_opening);
    if (v.direction != VibrationDirection::x && v.direction != VibrationDirection::z)
        reject_setting("vibration_direction", double(v.direction), "must be x (0) or z (1)");
    if (v.part != VibratingPart::bin && v.part != VibratingPart::hopper)
        reject_setting("vibration_part", double(v.part), "must be bin (0) or hopper (1)");
}

void validate_strength(const BinVibration& v) {
    if (!(v.frequency > 0 && v.amplitude > 0)) return;  // a still bin (its settings are refused elsewhere)
    // both settings named: either may be the one mistyped (0.01 Hz, or 1e-12 m)
    if (const std::string defect = vibration_peak_defect(v.amplitude, v.frequency); !defect.empty())
        throw SettingRejected("vibration_amplitude", v.amplitude, "vibration_frequency", v.frequency,
                              "gives " + defect);
}

BinVibrationMotion::BinVibrationMotion(const BinVibration& v) : v_(v) { validate(v_); }

void BinVibrationMotion::open_at(double opening_time) {
    if (law_) throw std::logic_error("BinVibrationMotion::open_at: the outlet opens once");
    start_ = opening_time + v_.start_after_opening;
    law_.emplace(axis_of(v_.direction), v_.amplitude, v_.frequency, start_);
}

std::optional<double> BinVibrationMotion::start_time() const {
    return law_ ? std::optional<double>(start_) : std::nullopt;
}

Vec3 BinVibrationMotion::displacement(double t) const { return law_ ? law_->displacement(t) : Vec3::Zero(); }

Vec3 BinVibrationMotion::velocity(double t) const { return law_ ? law_->velocity(t) : Vec3::Zero(); }

void BinVibrationMotion::append_numbers(std::vector<double>& c) const {
    if (law_) {
        law_->append_numbers(c);
        return;
    }
    // before the opening: a kind of its own (SinusoidalMotion is 1), then what the law will be
    const Vec3 e = axis_of(v_.direction);
    c.insert(c.end(), {2.0, e.x(), e.y(), e.z(), v_.amplitude, v_.frequency, v_.start_after_opening});
}

}  // namespace demcal::kernel::silo
