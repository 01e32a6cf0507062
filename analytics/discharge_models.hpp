// Analytical silo discharge models: Beverloo (circular orifice and rectangular slot), Johanson (mass flow, conical
// and wedge), Oldal's arch model (cylindrical) and its rectangular extension (seed, eq. 3.6), the Rose-Tanaka
// hopper-angle factor and Jenike's mass-flow limit for conical hoppers (Arnold-McLean approximation).
// SI units throughout, angles in degrees. Formulas: ../shared/reference/discharge-models.md; derivations checked in
// discharge_models.cpp.
#pragma once
#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace demcal::analytics {

inline constexpr double standard_gravity = 9.81;  // [m/s^2], the value the reference formulas use

enum class SiloShape { conical, rectangular };

// A silo, its outlet, the bulk solid and the model constants. Defaults are the usual literature values.
struct SiloGeometry {
    SiloShape shape = SiloShape::conical;
    double silo_diameter = 0;   // D [m], conical (cylindrical silo) only
    double depth = 0;           // b [m], rectangular only: silo depth, also the length of the slot outlet
    double width = 0;           // c [m], rectangular only: silo width, the outlet width a is measured along it
    double outlet = 0;          // d (circular outlet diameter) or a (slot width) [m]
    double half_angle_deg = 0;  // theta, hopper half angle from the vertical [deg], 90 = flat bottom
    double particle_size = 0;   // d_p [m]
    double bulk_density = 0;    // rho_b [kg/m^3]
    // Model constants
    double beverloo_c = 0.58;          // Beverloo C, circular orifice [-] (0.55-0.65)
    double beverloo_k = 1.5;           // Beverloo k, empty annulus in particle sizes [-] (1.4-1.6 for spheres)
    double slot_c = 1.03;              // Myers-Sellers C' for a rectangular slot [-]
    double arch_delta = 0.5;           // Oldal's arch shape coefficient delta [-] (apex height / effective outlet)
    double stagnant_angle_deg = 45;    // phi_d, stagnant-zone boundary to the horizontal, Rose-Tanaka [deg]
    std::optional<double> effective_friction_deg;  // delta_e, effective angle of internal friction [deg]
    std::optional<double> wall_friction_deg;       // phi_w, wall friction angle [deg]
};

// Throws std::invalid_argument naming the field and value for an impossible geometry (non-positive sizes, an outlet
// not larger than the particles or not smaller than the silo, angles out of range).
void validate(const SiloGeometry& g);

// The range a measured or given silo quantity can have, the same for a geometry file and a row of measured data:
// outlet_m, D_m, b_m, c_m (no silo is larger than 100 m), d_p_m (1 um powders to 1 m rocks), rho_b_kg_m3 (10 to
// 2e4 kg/m^3) and W_kg_s (up to 1e5 kg/s: the largest ship loaders discharge about 10 t/s). Throws
// std::invalid_argument "FIELD=VALUE outside [LO, HI] UNIT (WHY)", or "WHERE: VALUE outside ..." given `where`.
void check_plausible_silo_quantity(const std::string& field, double value, const std::string& where = "");

// One model's prediction with the reasons it may not apply.
struct DischargePrediction {
    std::string model;                  // e.g. "beverloo"
    std::optional<double> rate;         // W [kg/s]; empty when the model cannot be evaluated for this geometry
    bool valid = true;                  // false when used outside its range of validity
    std::vector<std::string> warnings;  // why it is not valid / not applicable
    nlohmann::json to_json() const;
};

// W = C rho_b sqrt(g) (d - k d_p)^2.5 (Beverloo et al. 1961). Zero when d <= k d_p.
double beverloo_rate(double outlet, double particle_size, double bulk_density, double c, double k);
// W = C' rho_b sqrt(g) (L - k d_p)(a - k d_p)^1.5 for a slot of length L and width a (Myers & Sellers).
double beverloo_slot_rate(double slot_length, double slot_width, double particle_size, double bulk_density, double c,
                          double k);
// Johanson's mass-flow rate W = rho_b A sqrt(B g / (2 (1 + m) tan(theta))): conical (m = 1, A = pi d^2/4, B = d) or
// wedge (m = 0, A = L a, B = a).
double johanson_conical_rate(double outlet, double half_angle_deg, double bulk_density);
double johanson_wedge_rate(double slot_length, double slot_width, double half_angle_deg, double bulk_density);
// Oldal's arch model, circular outlet: W = (pi sqrt(2g)/6) sqrt(delta) rho_b (d - d_p)^2.5.
double oldal_rate(double outlet, double particle_size, double bulk_density, double delta);
// Its rectangular extension (seed eq. 3.6): W = (pi sqrt(2g)/4) sqrt(delta) rho_b b (a - d_p)^1.5.
double oldal_rectangular_rate(double depth, double outlet, double particle_size, double bulk_density, double delta);
// Rose-Tanaka factor F = (tan theta tan phi_d)^-0.35 for theta < 90 - phi_d, else 1 (multiplies Beverloo).
double rose_tanaka_factor(double half_angle_deg, double stagnant_angle_deg);
// Jenike's limiting conical half angle for mass flow (Arnold-McLean approximation of the design chart):
// theta_c = 90 - arccos((1 - sin de)/(2 sin de))/2 - (phi_w + arcsin(sin phi_w / sin de))/2 [deg].
// Throws std::invalid_argument when phi_w >= delta_e (no mass flow is possible) or angles are out of range.
double jenike_mass_flow_limit_deg(double effective_friction_deg, double wall_friction_deg);

// The validity limits of the rectangular Oldal model (seed): 1 <= c/b <= 4 and 0.15 <= a/c <= 0.7.
// Returns one message per limit violated (empty when within its limits).
std::vector<std::string> oldal_rectangular_limit_violations(double depth, double width, double outlet);

// Every model's rate for the geometry, with its validity.
std::vector<DischargePrediction> predict_discharge(const SiloGeometry& g);

// Reads a geometry from JSON (keys documented in examples/diagnose/README.md); rejects unknown keys, missing keys and
// impossible values with std::invalid_argument naming the key and value.
SiloGeometry geometry_from_json(const nlohmann::json& j);

}  // namespace demcal::analytics
