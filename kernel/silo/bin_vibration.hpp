// The seed's vibrational discharge (sections 2.1.3, 3.5): an eccentric vibrator fixed on the conical bin shakes it as
// d(t) = A sin(2 pi f (t - t0)), perpendicular to the silo axis in the lab. The walls it moves are a choice
// (VibratingPart): the whole bin as one rigid body, or the hopper alone. Here the bin is still while it fills and
// starts to vibrate a chosen delay after the outlet opens.
#pragma once
#include "kernel/walls/wall_motion.hpp"

#include <cstdint>
#include <optional>
#include <string>

namespace demcal::kernel::silo {

enum class VibrationDirection : std::int32_t {
    x = 0,  // horizontal, perpendicular to the silo axis (the seed's vibrator; across the slot of a rectangular bin)
    z = 1,  // along the axis (vertical)
};
std::string to_string(VibrationDirection d);

// Which walls the vibrator moves (all on the same law).
enum class VibratingPart : std::int32_t {
    bin = 0,     // hopper, body and outlet plate, as one rigid body
    hopper = 1,  // the hopper (the cone; a rectangular bin's two slanted walls) and the outlet plate; the body and a
                 // rectangular bin's front and back walls stay still. The seed's vibrator sits on the cone and its
                 // accelerometer measured the cone: how much of that motion reached the body was not measured.
};
std::string to_string(VibratingPart p);
// The part of a name as to_string gives it; empty for any other text.
std::optional<VibratingPart> vibrating_part_named(const std::string& name);

struct BinVibration {
    double frequency = 0;            // f [Hz]; 0: still
    double amplitude = 0;            // A [m] of the displacement; 0: still
    VibrationDirection direction = VibrationDirection::x;
    double start_after_opening = 0;  // [s] from the opening of the outlet (0: the bin vibrates as it opens)
    VibratingPart part = VibratingPart::bin;

    bool vibrates() const { return frequency > 0 && amplitude > 0; }
    double peak_acceleration() const;  // A (2 pi f)^2 [m/s^2]
    double peak_velocity() const;      // A 2 pi f [m/s]
};

// Throws std::invalid_argument naming the field and the value: f in [0, 1000] Hz, A in [0, 0.01] m, the start
// >= 0 s, each finite and not subnormal; a known direction and part. The checks that need the rest of the run (time
// step, removal depth) are in validate(SiloCaseSettings).
void validate(const BinVibration& v);
// The shaking's strength: its peak acceleration at most kMaxVibrationPeakAcceleration (kernel/walls/wall_motion.hpp).
// Apart from validate, so that a case checks it after the rules with more telling reasons (time steps per period).
void validate_strength(const BinVibration& v);

// The law every vibrating wall shares. The opening time is only known when the filling ends (at rest, or at its time
// limit), after the walls were built: until open_at() is called the bin stays still; then the sinusoid starts
// start_after_opening later. A resumed run calls open_at() with the stored opening time before it adds the walls, so
// that the law (part of the kernel's configuration check) is the one the checkpoint was written with.
class BinVibrationMotion final : public WallMotion {
public:
    explicit BinVibrationMotion(const BinVibration& v);
    // Once, at the opening (simulated time [s]).
    void open_at(double opening_time);
    // The absolute start of the sinusoid [s]; empty before the opening.
    std::optional<double> start_time() const;

    Vec3 displacement(double t) const override;
    Vec3 velocity(double t) const override;
    void append_numbers(std::vector<double>& c) const override;

private:
    BinVibration v_;
    std::optional<SinusoidalMotion> law_;  // set at the opening
    double start_ = 0;                     // the law's start, once set
};

}  // namespace demcal::kernel::silo
