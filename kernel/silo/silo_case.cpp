#include "kernel/silo/silo_case.hpp"
#include "kernel/silo/input_error.hpp"

#include "kernel/clump.hpp"
#include "kernel/contact/hertz_normal.hpp"
#include "kernel/process_time.hpp"
#include "kernel/simulation.hpp"
#include "kernel/walls.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <type_traits>
#include <unordered_map>

namespace demcal::kernel::silo {

namespace {

constexpr double pi = 3.14159265358979323846;


// Random sequential addition of rigid clumps (no overlap) into the silo, slab by slab from the outlet upwards.
// Slabs above the silo's top extend the body (the "generation column"); the caller extends the body wall to match.
class Generator {
public:
    Generator(const SiloGeometry& g, const ClumpTemplate& t, unsigned long seed)
        : g_(g), t_(t), rng_(seed), cell_(2 * *std::max_element(t.radii.begin(), t.radii.end())) {}

    struct Placed {
        Vec3 com;
        Quat q;  // template frame -> world
    };

    std::vector<Placed> generate(long n, double slab, double attempts_per_volume) {
        std::vector<Placed> out;
        out.reserve(n);
        std::uniform_real_distribution<double> u(0, 1);
        double z0 = 0;
        const double vgrain = t_.volume;
        // template-frame member positions relative to the template's centre of mass
        std::vector<Vec3> rel;
        for (const auto& p : t_.positions) rel.push_back(p - t_.com);
        int empty_slabs = 0;
        while (long(out.size()) < n) {
            const double z1 = z0 + slab;
            const double half = g_.half_size_at(z1);
            // candidate box: the silo's cross-section bounding box at the slab's top
            const double hx = half, hy = g_.shape == SiloShape::conical ? half : 0.5 * g_.depth;
            const double area = g_.shape == SiloShape::conical ? pi * half * half : 4 * hx * hy;
            const long attempts = std::max<long>(50, long(attempts_per_volume * area * slab / vgrain));
            long placed_here = 0;
            for (long a = 0; a < attempts && long(out.size()) < n; ++a) {
                const Vec3 c((2 * u(rng_) - 1) * hx, (2 * u(rng_) - 1) * hy, z0 + u(rng_) * slab);
                // uniform random rotation (Shoemake)
                const double u1 = u(rng_), u2 = 2 * pi * u(rng_), u3 = 2 * pi * u(rng_);
                const double s1 = std::sqrt(1 - u1), s2 = std::sqrt(u1);
                const Quat q(s2 * std::cos(u3), s1 * std::sin(u2), s1 * std::cos(u2), s2 * std::sin(u3));
                bool ok = true;
                std::vector<Vec3> members;
                for (size_t m = 0; m < rel.size() && ok; ++m) {
                    const Vec3 p = c + q * rel[m];
                    if (!inside(p, t_.radii[m])) ok = false;
                    members.push_back(p);
                }
                for (size_t m = 0; m < members.size() && ok; ++m) ok = free(members[m], t_.radii[m]);
                if (!ok) continue;
                for (size_t m = 0; m < members.size(); ++m) insert(members[m], t_.radii[m]);
                out.push_back({c, q});
                ++placed_here;
            }
            empty_slabs = placed_here ? 0 : empty_slabs + 1;
            if (empty_slabs > 20) throw std::runtime_error("generation: no grain fits in 20 successive slabs");
            z0 = z1;
        }
        top_ = z0;
        return out;
    }
    double top() const { return top_; }

private:
    bool inside(const Vec3& p, double r) const {
        const double clearance = 1e-5;
        if (p.z() - r < clearance) return false;
        // body walls extended above the silo's top for the generation column
        SiloGeometry tall = g_;
        tall.body_height = 1e9;
        return tall.distance_to_side_wall(p) >= r + clearance;
    }
    long long key(int i, int j, int k) const {
        return ((long long)(i + 100000) * 200000LL + (j + 100000)) * 400000LL + (k + 100000);
    }
    bool free(const Vec3& p, double r) const {
        const int ci = int(std::floor(p.x() / cell_)), cj = int(std::floor(p.y() / cell_)),
                  ck = int(std::floor(p.z() / cell_));
        for (int i = ci - 1; i <= ci + 1; ++i)
            for (int j = cj - 1; j <= cj + 1; ++j)
                for (int k = ck - 1; k <= ck + 1; ++k) {
                    auto it = grid_.find(key(i, j, k));
                    if (it == grid_.end()) continue;
                    for (const auto& [q, rq] : it->second)
                        if ((q - p).squaredNorm() < (r + rq + 1e-5) * (r + rq + 1e-5)) return false;
                }
        return true;
    }
    void insert(const Vec3& p, double r) {
        grid_[key(int(std::floor(p.x() / cell_)), int(std::floor(p.y() / cell_)), int(std::floor(p.z() / cell_)))]
            .push_back({p, r});
    }

    SiloGeometry g_;
    const ClumpTemplate& t_;
    std::mt19937_64 rng_;
    double cell_;
    double top_ = 0;
    std::unordered_map<long long, std::vector<std::pair<Vec3, double>>> grid_;
};

kernel::Material to_kernel(const silo::Material& m, const char* name) {
    kernel::Material k;
    k.young = m.young();
    k.poisson = m.poisson;
    k.density = m.density;
    k.name = name;
    return k;
}

// The pair's inputs of the law the run is on: the cohesion and the rolling friction only where the law has them (a
// law without them runs only materials without them: run_on_its_law's choice, validate's refusal).
template <class Law>
typename Law::Params to_kernel(const PairCoefficients& p) {
    typename Law::Params k;
    k.restitution = p.restitution;
    k.friction = p.friction;
    if constexpr (requires { k.rolling_friction; }) k.rolling_friction = p.rolling_friction;
    if constexpr (requires { k.surface_energy; }) k.surface_energy = p.surface_energy;
    return k;
}

// The walls in the order silo_walls gives them, then (facets > 0) the facet walls of silo_facet_walls, switched off
// until the opening (silo_exact_wall_count, open()); returns the outlet plate's wall id.
template <class Sim>
int add_silo_walls(Sim& sim, const SiloGeometry& g, int steel, double wall_top,
                   const std::shared_ptr<const WallMotion>& bin_motion, VibratingPart part, int facets) {
    int plate = -1;
    for (const Wall& w : silo_walls(g, steel, wall_top, bin_motion, part)) plate = sim.add_wall(w);
    if (facets > 0)
        for (const Wall& w : silo_facet_walls(g, steel, wall_top, facets, bin_motion, part))
            sim.set_wall_enabled(sim.add_wall(w), false);
    return plate;
}

// The walls the facets replace at the opening: silo_walls' cone and cylinder, ids 0 and 1.
constexpr int silo_exact_wall_count = 2;

}  // namespace

std::vector<Wall> silo_walls(const SiloGeometry& g, int steel, double wall_top,
                             const std::shared_ptr<const WallMotion>& bin_motion, VibratingPart part) {
    std::vector<Wall> walls;
    const auto hopper = [&](const Wall& w) { walls.push_back(bin_motion ? w.moving(bin_motion) : w); };
    const auto body = [&](const Wall& w) {
        walls.push_back(bin_motion && part == VibratingPart::bin ? w.moving(bin_motion) : w);
    };
    const double hh = g.hopper_height(), th = g.half_angle_deg * pi / 180;
    if (g.shape == SiloShape::conical) {
        const double r0 = g.outlet_half(), R = g.top_half();
        hopper(Wall::cone(0, 0, r0, 0, th, R, steel));
        body(Wall::cylinder(0, 0, R, hh, wall_top, steel));
        hopper(Wall::disk(0, 0, r0 * 1.001, 0, steel));
        return walls;
    }
    const double a2 = 0.5 * g.outlet, b2 = 0.5 * g.depth, c2 = 0.5 * g.width;
    for (double s : {-1.0, 1.0}) {
        // slanted hopper wall from the outlet edge (x = s a/2, z = 0) to the body (x = s c/2, z = hh), full depth
        hopper(Wall::rectangle_from_corners(Vec3(s * a2, -b2, 0), Vec3(s * a2, b2, 0), Vec3(s * c2, -b2, hh), steel));
        // vertical body wall x = s c/2
        body(Wall::rectangle_from_corners(Vec3(s * c2, -b2, hh), Vec3(s * c2, b2, hh), Vec3(s * c2, -b2, wall_top),
                                          steel));
        // front/back wall y = s b/2 over the whole height (the part outside the hopper is never reached)
        body(Wall::rectangle_from_corners(Vec3(-c2, s * b2, 0), Vec3(c2, s * b2, 0), Vec3(-c2, s * b2, wall_top),
                                          steel));
    }
    hopper(Wall::rectangle(Vec3(0, 0, 0), Vec3::UnitZ(), Vec3::UnitX(), a2 * 1.001, b2, steel));
    return walls;
}

std::vector<Wall> silo_facet_walls(const SiloGeometry& g, int steel, double wall_top, int sides,
                                   const std::shared_ptr<const WallMotion>& bin_motion, VibratingPart part) {
    if (g.shape != SiloShape::conical)
        throw std::invalid_argument("silo_facet_walls: facet walls are built for the conical silo only");
    // a polygon of `sides` whose sides lie at mean distance `radius` from the axis (silo.py's ring())
    const auto ring = [sides](double radius, double z) {
        const double vertex_radius = radius * (pi / sides) / std::sin(pi / sides);
        std::vector<Vec3> v;
        for (int k = 0; k < sides; ++k)
            v.emplace_back(vertex_radius * std::cos(2 * pi * k / sides), vertex_radius * std::sin(2 * pi * k / sides), z);
        return v;
    };
    const double hh = g.hopper_height();
    const std::vector<Vec3> outlet = ring(g.outlet_half(), 0.0), body = ring(g.top_half(), hh),
                            top = ring(g.top_half(), wall_top);
    std::vector<Wall> walls;
    // two triangles per side between two rings (silo.py's band_facets): (a, b, c) and (a, c, d)
    const auto band = [&](const std::vector<Vec3>& lower, const std::vector<Vec3>& upper, bool moves) {
        for (int k = 0; k < sides; ++k) {
            const int m = (k + 1) % sides;
            for (const Wall& w : {Wall::triangle(lower[k], lower[m], upper[m], steel),
                                  Wall::triangle(lower[k], upper[m], upper[k], steel)})
                walls.push_back(moves ? w.moving(bin_motion) : w);
        }
    };
    band(outlet, body, bin_motion != nullptr);                                  // the cone: the hopper
    band(body, top, bin_motion != nullptr && part == VibratingPart::bin);       // the cylinder: the body
    return walls;
}

// The grain's length, which sets the outlet's particle size and the filling's rest criterion.
double grain_length(const WheatMaterials& m) {
    return m.grain_aspect_ratio == wheat_aspect_ratio ? wheat_length
                                                      : clump_length(elongated_wheat_clump(m.grain_aspect_ratio));
}

namespace {
// The radius of the grain's smallest sphere: it sets the stiffest contact's time step and the overlap a grain bears.
double smallest_sphere_radius(const WheatMaterials& m) {
    double smallest_radius = 1;
    for (const auto& sphere : elongated_wheat_clump(m.grain_aspect_ratio))
        smallest_radius = std::min(smallest_radius, sphere.radius);
    return smallest_radius;
}
}  // namespace

double smallest_sphere_rayleigh_step(const WheatMaterials& m) {
    return rayleigh_time_step(m.wheat_scaled(), smallest_sphere_radius(m));
}

double planned_time_step(const SiloCaseSettings& s) {
    return s.time_step > 0 ? s.time_step : s.time_step_fraction * smallest_sphere_rayleigh_step(s.materials);
}

// The largest sliding friction coefficient a pair may have (tan 63 deg).
constexpr double kMaxFriction = 2;

void validate(const WheatMaterials& materials) {
    // the fields by the names of the material file (app/silo_material.hpp: examples/materials/silo_wheat_table21.json)
    const auto solid = [](const Material& m, const std::string& name) {
        if (!(m.shear_modulus >= 1e3 && m.shear_modulus <= 1e12))
            reject_setting(name + ".shear_modulus_Pa", m.shear_modulus, "must lie in [1e3, 1e12] Pa");
        if (!(m.poisson > -1 && m.poisson < 0.5)) reject_setting(name + ".poisson", m.poisson, "must lie in (-1, 0.5)");
        if (!(m.density >= 10 && m.density <= 1e5))
            reject_setting(name + ".density_kg_m3", m.density, "must lie in [10, 1e5] kg/m^3");
    };
    solid(materials.wheat, "grain");
    solid(materials.steel, "wall");
    const auto pair = [](const PairCoefficients& p, const std::string& name) {
        if (!(p.restitution > 0 && p.restitution <= 1))
            reject_setting(name + ".restitution", p.restitution, "must lie in (0, 1]");
        // a sliding friction coefficient above 2 (63 deg) has not been measured for grains on grains or on steel
        // (Table 2.1: 0.3 and 0.25); friction 10 was taken (held-back suite)
        if (!(p.friction >= 0 && p.friction <= kMaxFriction))
            reject_setting(name + ".friction", p.friction,
                           "must lie in [0, " + setting_text(kMaxFriction) +
                               "] (a Coulomb coefficient, tan of the sliding angle; Table 2.1: 0.3 and 0.25)");
        if (!(p.rolling_friction >= 0 && p.rolling_friction <= 1))
            reject_setting(name + ".rolling_friction", p.rolling_friction, "must lie in [0, 1]");
        // 100 J/m^2 gives the seed's grain a bond number 3 pi gamma R* / (m g) near 2000: far beyond any powder
        if (!(p.surface_energy >= 0 && p.surface_energy <= 100))
            reject_setting(name + ".surface_energy_J_m2", p.surface_energy, "must lie in [0, 100] J/m^2 (0: no cohesion)");
    };
    pair(materials.wheat_wheat, "grain_grain");
    pair(materials.wheat_steel, "grain_wall");
    if (!(materials.grain_aspect_ratio >= min_grain_aspect_ratio && materials.grain_aspect_ratio <= max_grain_aspect_ratio))
        reject_setting("grain.aspect_ratio", materials.grain_aspect_ratio,
                       "must lie in [1, 2.6] (length / width of the 3-sphere grain; the seed's 1.833)");
}

namespace {

double mass_of_grain(const WheatMaterials& m) { return m.wheat.density * wheat_grain_volume(); }

// The bed must fit the silo: `--particles 5e6` in the 105 mm silo passed the check, and its grains (36 times the
// silo's volume) would have been generated in a column 30 m tall and spilled over the silo's top. The bound is the
// densest packing grains can have (0.74, equal spheres in a lattice; random beds of spheres or elongated grains stay
// below it), so that only a bed that cannot fit is refused, never a full silo.
constexpr double kDensestSolidFraction = 0.74;
void validate_bed_fits(const SiloCaseSettings& s, double grain_mass) {
    const double grains = s.fill_mass > 0 ? s.fill_mass / grain_mass : double(s.particles);
    const double grain_volume = grain_mass / s.materials.wheat.density;
    const double smallest_bed = grains * grain_volume / kDensestSolidFraction;
    if (smallest_bed <= s.geometry.volume()) return;
    const bool by_mass = s.fill_mass > 0;
    reject_setting(by_mass ? "fill_mass" : "particles", by_mass ? s.fill_mass : double(s.particles),
                   "the bed does not fit the silo: its grains fill at least " + setting_text(smallest_bed) +
                       " m^3 (at a solid fraction of " + setting_text(kDensestSolidFraction) +
                       ", the densest packing), and the hopper and the body hold " +
                       setting_text(s.geometry.volume()) + " m^3 (body height " +
                       setting_text(s.geometry.body_height) + " m): fewer grains, or a taller body");
}

// The bed: a fill mass or a particle count, many grains and not beyond memory.
void validate_bed_size(const SiloCaseSettings& s) {
    if (s.fill_mass < 0 || !std::isfinite(s.fill_mass)) reject_setting("fill_mass", s.fill_mass, "must be >= 0 kg");
    // a bed is many grains: one grain has no bulk density, no flow pattern and no steady rate (`--particles 1` ran,
    // reported a bulk density of 0 and no rate, exit 0)
    constexpr int kMinGrains = 10;
    if (s.fill_mass == 0 && s.particles < kMinGrains)
        reject_setting("particles", double(s.particles),
                       "must be at least " + std::to_string(kMinGrains) + " (a bed, not a few grains)");
    constexpr double kMaxGrains = 5e6;  // 15e6 spheres: about 9 GB of state, beyond any machine this runs on
    if (s.particles > kMaxGrains) reject_setting("particles", double(s.particles), "more than 5,000,000 grains");
    const double grain_mass = mass_of_grain(s.materials);
    if (s.fill_mass > 0 && s.fill_mass < (kMinGrains - 0.5) * grain_mass)  // (below one grain it was silently one)
        reject_setting("fill_mass", s.fill_mass,
                       "less than " + std::to_string(kMinGrains) + " grains of " + setting_text(grain_mass * 1e3) +
                           " g (a bed, not a few grains)");
    if (s.fill_mass / grain_mass > kMaxGrains)
        reject_setting("fill_mass", s.fill_mass,
                       "more than 5,000,000 grains of " + setting_text(grain_mass * 1e3) + " g");
    validate_bed_fits(s, grain_mass);
}

// The stiffness and the time step: resolved, not needlessly fine.
void validate_time_step(const SiloCaseSettings& s) {
    // a softening of the measured stiffness for a longer time step; above 1 the grains would be stiffer than the
    // material measured and the run only slower (100 was taken: held-back suite)
    if (!(s.materials.stiffness_scale > 0) || s.materials.stiffness_scale > 1)
        reject_setting("stiffness_scale", s.materials.stiffness_scale,
                       "must lie in (0, 1]: it softens the material's measured stiffness (1: as measured)");
    if (s.time_step < 0 || !std::isfinite(s.time_step)) reject_setting("dt", s.time_step, "must be >= 0 s (0: automatic)");
    // beyond the Rayleigh step the explicit integration of the stiffest contact is no longer resolved
    const double rayleigh = smallest_sphere_rayleigh_step(s.materials);
    if (s.time_step > rayleigh)
        reject_setting("dt", s.time_step,
                       "larger than the Rayleigh time step of the smallest wheat sphere (" + setting_text(rayleigh) +
                           " s at this stiffness); use a fraction of it, or --dt-fraction");
    // Below a thousandth of the Rayleigh step nothing is resolved better (at 0.25 a contact already spans tens of
    // steps), and the run would take up to a thousand times the steps (--dt-fraction 1e-5 passed the step count; a
    // stop then waited for the end of a record interval of millions of steps, before stops came within one step)
    if (s.time_step > 0 && s.time_step < kMinTimeStepFraction * rayleigh)
        reject_setting("dt", s.time_step,
                       "smaller than " + setting_text(kMinTimeStepFraction) + " of the Rayleigh time step of the "
                       "smallest wheat sphere (" + setting_text(rayleigh) + " s at this stiffness): no more accurate, "
                       "and the run would take up to a thousand times the steps");
    if (!(s.time_step_fraction >= kMinTimeStepFraction && s.time_step_fraction <= 1))
        reject_setting("dt_fraction", s.time_step_fraction,
                       "must lie in [" + setting_text(kMinTimeStepFraction) +
                           ", 1] (of the Rayleigh time step; smaller is no more accurate, and the run would take up "
                           "to a thousand times the steps)");
}

// The contact law and the discharge's options, and what the yade law cannot carry.
void validate_contact_options(const SiloCaseSettings& s) {
    if (s.contact_law != SiloContactLaw::edem && s.contact_law != SiloContactLaw::yade)
        reject_setting("contact_law", static_cast<double>(s.contact_law), "must be edem (0) or yade (1)");
    if (s.discharge_wall_facets != 0) {
        if (!(s.discharge_wall_facets >= 12 && s.discharge_wall_facets <= 2000))
            reject_setting("discharge_wall_facets", s.discharge_wall_facets,
                           "must be 0 (exact walls) or lie in [12, 2000] (facets around)");
        if (s.geometry.shape != SiloShape::conical)
            reject_setting("discharge_wall_facets", s.discharge_wall_facets,
                           "facet walls are built for the conical silo only (0 for a rectangular one)");
    }
    if (s.discharge_clump_rotation != ClumpRotation::richardson &&
        s.discharge_clump_rotation != ClumpRotation::yade_leapfrog)
        reject_setting("discharge_clump_rotation", static_cast<double>(s.discharge_clump_rotation),
                       "must be richardson (0) or yade (1)");
    if (s.contact_law == SiloContactLaw::yade) {
        // YADE's Hertz-Mindlin (as silo.py runs it) has neither: a value would be silently dropped
        for (const auto& [p, name] : {std::pair{&s.materials.wheat_wheat, "grain_grain"},
                                      std::pair{&s.materials.wheat_steel, "grain_wall"}}) {
            if (p->surface_energy != 0)
                reject_setting(std::string(name) + ".surface_energy", p->surface_energy,
                               "the yade contact law has no cohesion (use the edem law, JKR)");
            if (p->rolling_friction != 0)
                reject_setting(std::string(name) + ".rolling_friction", p->rolling_friction,
                               "the yade contact law has no rolling resistance (as yade_scripts/silo.py's default): "
                               "set it to 0, or use the edem law");
        }
    }
    if (s.contacts_at_opening != ContactsAtOpening::keep_history &&
        s.contacts_at_opening != ContactsAtOpening::forget_history &&
        s.contacts_at_opening != ContactsAtOpening::yade_import)
        reject_setting("contacts_at_opening", static_cast<double>(s.contacts_at_opening),
                       "must be keep_history (0), forget_history (1) or yade_import (2)");
}

// The vibration against the run: resolved by the time step, started in time, above the removal plane.
void validate_vibration_in_run(const SiloCaseSettings& s) {
    if (s.vibration.vibrates()) {
        // a period resolved by fewer steps would alias: the walls jump rather than oscillate
        constexpr double kStepsPerPeriod = 20;
        const double dt = planned_time_step(s);
        if (s.vibration.frequency * dt * kStepsPerPeriod > 1)
            reject_setting("vibration_frequency", s.vibration.frequency,
                           "a period is only " + setting_text(1 / (s.vibration.frequency * dt)) + " time steps of " +
                               setting_text(dt) + " s; at most " + setting_text(1 / (kStepsPerPeriod * dt)) +
                               " Hz at this time step (20 steps per period), or a smaller --dt-fraction");
        if (s.vibration.start_after_opening >= s.max_time)
            reject_setting("vibration_start", s.vibration.start_after_opening,
                           "not before the discharge's time limit (max_time = " + setting_text(s.max_time) +
                               " s after the opening): the bin would never vibrate");
        // grains count as discharged below a fixed plane: the vibrating outlet must stay above it
        if (s.vibration.direction == VibrationDirection::z && s.vibration.amplitude >= 0.5 * s.removal_depth)
            reject_setting("vibration_amplitude", s.vibration.amplitude,
                           "along z the outlet would come within half the removal depth (" +
                               setting_text(s.removal_depth) + " m) of the plane below which grains count as "
                               "discharged: at most " + setting_text(0.5 * s.removal_depth) + " m along z");
    }
}

// A stop fraction that leaves too few grains in the rate's window (between steady_lower and steady_upper of the
// mass discharged) for a slope: --stop-fraction 0.01 of 300 grains fitted a "rate" on 2 grains (held-back suite).
constexpr double kMinGrainsInRateWindow = 10;
void validate_rate_window_grains(const SiloCaseSettings& s) {
    if (s.stop_fraction >= 1) return;  // every grain may leave: the bed's own size rules apply
    const double grains = s.fill_mass > 0 ? s.fill_mass / mass_of_grain(s.materials) : double(s.particles);
    const double in_window = s.stop_fraction * grains * (s.steady_upper - s.steady_lower);
    if (in_window < kMinGrainsInRateWindow)
        reject_setting("stop_fraction", s.stop_fraction,
                       "of " + setting_text(std::round(grains)) + " grains leaves " + setting_text(in_window) +
                           " grains between " + setting_text(100 * s.steady_lower) + " % and " +
                           setting_text(100 * s.steady_upper) + " % of the discharged mass, where the rate is " +
                           "fitted: at least " + setting_text(kMinGrainsInRateWindow) +
                           " are needed; a larger fraction or more grains");
}

// Times, intervals, threads and the steady window.
void validate_run_control(const SiloCaseSettings& s) {
    if (!(s.fill_time_max > 0) || !std::isfinite(s.fill_time_max)) reject_setting("fill_time", s.fill_time_max, "must be > 0 s");
    if (!(s.max_time > 0) || !std::isfinite(s.max_time)) reject_setting("max_time", s.max_time, "must be > 0 s");
    if (!(s.stop_fraction > 0 && s.stop_fraction <= 1))
        reject_setting("stop_fraction", s.stop_fraction, "must lie in (0, 1]");
    validate_rate_window_grains(s);
    if (!(s.threads >= 1)) reject_setting("threads", s.threads, "must be at least 1");
    if (!(s.skin >= 0) || s.skin > 0.01) reject_setting("skin", s.skin, "must lie in [0, 0.01] m (0: automatic)");
    if (!s.vtk_dir.empty() && !(s.vtk_interval > 0)) reject_setting("vtk_every", s.vtk_interval, "must be > 0 s");
    if (!(s.record_interval > 0)) reject_setting("record_interval", s.record_interval, "must be > 0 s");
    if (!(s.checkpoint_interval >= 0) || !std::isfinite(s.checkpoint_interval))
        reject_setting("checkpoint_interval", s.checkpoint_interval, "must be >= 0 s (0: every record interval)");
    if (!(s.wall_limit >= 0) || !std::isfinite(s.wall_limit))
        reject_setting("wall_limit", s.wall_limit, "must be >= 0 s (0: none)");
    if (s.wall_limit > 0 && s.checkpoint_file.empty())
        reject_setting("wall_limit", s.wall_limit, "needs a checkpoint file: a run stopped at the limit resumes from it");
    if (!(s.steady_lower >= 0 && s.steady_lower < s.steady_upper && s.steady_upper <= 1))
        reject_setting("steady_lower", s.steady_lower, "the steady window must satisfy 0 <= lower < upper <= 1");
}

void validate_contact_softness(const SiloCaseSettings& s) {
  // Contacts so soft that a grain meeting another, or a wall, at the speed of a fall through the whole silo would
  // overlap by more than the smallest sphere's radius pass through (a stiffness_scale of 1e-12 gave a 2 s time step and
  // every grain fell through the walls; a wall of G = 1 kPa let every grain through, reported as an empty silo with
  // exit 0). Two grains head on: m* = m/2, R* = r/2, E* = E/(2(1-nu^2)); a grain on a wall: m* = m, R* = r,
  // 1/E* = (1-nu^2)/E + (1-nu_w^2)/E_w. The reduced cases' 1e-3 gives 0.6 r; 1e-4 would give 1.6 r.
  const double grain_mass = mass_of_grain(s.materials);
  const double smallest_radius = smallest_sphere_radius(s.materials);
  const Material grain = s.materials.wheat_scaled(), wall = s.materials.steel_scaled();
  const auto young = [](const Material& m) { return 2 * m.shear_modulus * (1 + m.poisson); };
  const auto compliance = [&](const Material& m) { return (1 - m.poisson * m.poisson) / young(m); };
  const double speed = std::sqrt(2 * std::abs(s.gravity) * s.geometry.top()) +
                       (s.vibration.vibrates() ? s.vibration.peak_velocity() : 0.0);
  const double grains_overlap =
      hertz_impact_overlap(0.5 * grain_mass, 0.5 * smallest_radius, 1 / (2 * compliance(grain)), speed);
  const double wall_overlap =
      hertz_impact_overlap(grain_mass, smallest_radius, 1 / (compliance(grain) + compliance(wall)), speed);
  const std::string meeting = " m/s (a fall through the silo) would overlap by ";
  if (!(grains_overlap <= smallest_radius))
    reject_setting("stiffness_scale", s.materials.stiffness_scale,
                   "makes the grains so soft that two meeting at " + setting_text(speed) + meeting +
                       setting_text(grains_overlap / smallest_radius) +
                       " sphere radii: they would pass through each other; at least " +
                       setting_text(s.materials.stiffness_scale * std::pow(grains_overlap / smallest_radius, 2.5)) +
                       " for this material and silo");
  if (!(wall_overlap <= smallest_radius))
    reject_setting("wall.shear_modulus_Pa", s.materials.steel.shear_modulus,
                   "scaled by the stiffness scale " + setting_text(s.materials.stiffness_scale) +
                       ", makes the walls so soft that a grain meeting one at " + setting_text(speed) + meeting +
                       setting_text(wall_overlap / smallest_radius) +
                       " sphere radii: it would pass through the wall");
}

}  // namespace

void validate(const SiloCaseSettings& s) {
    validate(s.materials);  // first: the checks below derive masses and time steps from them
    validate(s.geometry, grain_length(s.materials));
    validate_bed_size(s);
    validate_time_step(s);
    validate(s.vibration);
    validate_contact_options(s);
    validate_vibration_in_run(s);
    validate_run_control(s);
    validate_contact_softness(s);  // the checks above name a more specific cause first
    validate_strength(s.vibration);  // last: the time step and the grains' softness are more telling reasons
}

namespace {

// Version 12: the filling's CPU time after the discharge record's count of CPU sessions (versions 4 to 11 are read:
// the filling's CPU unknown when the run was past it).
// Version 11: the discharge's wall facets at the end of the settings (versions 4 to 10 are read, exact walls).
// Version 10: the discharge's clump rotation scheme at the end of the settings (versions 4 to 9 are read, richardson).
// Version 9: the contact law (edem / yade) at the end of the settings (versions 4 to 8 are read, on the edem law).
// Version 8: the grain's aspect ratio at the end of the settings (versions 4 to 7 are read, with the seed's grain).
// Version 5: the pairs' surface energies (JKR cohesion) at the end of the settings; version 4, the same without them
// (no cohesion), is read too. Version 4: each section (tag and settings; the case's state; the kernel's state) closed
// by a checksum, the kernel's state in its format 3 (contact histories of any size, moving walls); the settings
// include the bin's vibration (version 3 had none). Versions 1 to 3 are refused with a message that says so.
// Version 13: the steps left of the record interval a session stopped within (its kernel state owes a half kick);
// versions 4 to 12 stopped only at the end of an interval (0 left).
constexpr const char* kCheckpointTagPrefix = "demcal-silo-checkpoint/";
constexpr int kCheckpointVersion = 13;
constexpr int kCheckpointVersionWithoutIntervalStop = 12;  // interval_steps_left_: 0
constexpr int kCheckpointVersionWithoutFillCpu = 11;       // fill_cpu_s: unknown past the filling
constexpr int kCheckpointVersionWithoutWallFacets = 10;    // discharge_wall_facets: 0 (exact walls)
constexpr int kCheckpointVersionWithoutRotationChoice = 9;  // discharge_clump_rotation: richardson
constexpr int kCheckpointVersionWithoutLawChoice = 8;      // contact_law: edem
constexpr int kCheckpointVersionWithoutGrainShape = 7;     // grain_aspect_ratio: the seed's
constexpr int kCheckpointVersionWithoutVibratingPart = 6;  // vibration_part: bin; no outlet-flow frames
constexpr int kCheckpointVersionWithoutHistoryChoice = 5;  // contacts_at_opening: keep_history
constexpr int kCheckpointVersionWithoutCohesion = 4;

// Every setting that shapes the run, named once: the checkpoint stores the settings through this list.
template <class S, class F>
void for_each_setting(S& s, F&& f) {
    f("shape", s.geometry.shape);
    f("diameter", s.geometry.diameter);
    f("body_height", s.geometry.body_height);
    f("theta", s.geometry.half_angle_deg);
    f("outlet", s.geometry.outlet);
    f("depth", s.geometry.depth);
    f("width", s.geometry.width);
    for (auto* m : {&s.materials.wheat, &s.materials.steel}) {
        f("shear_modulus", m->shear_modulus);
        f("poisson", m->poisson);
        f("density", m->density);
    }
    for (auto* p : {&s.materials.wheat_wheat, &s.materials.wheat_steel}) {
        f("restitution", p->restitution);
        f("friction", p->friction);
        f("rolling_friction", p->rolling_friction);
    }
    f("stiffness_scale", s.materials.stiffness_scale);
    f("particles", s.particles);
    f("fill_mass", s.fill_mass);
    f("gravity", s.gravity);
    f("time_step", s.time_step);
    f("time_step_fraction", s.time_step_fraction);
    f("fill_time_min", s.fill_time_min);
    f("fill_time_max", s.fill_time_max);
    f("rest_energy_factor", s.rest_energy_factor);
    f("max_time", s.max_time);
    f("stop_fraction", s.stop_fraction);
    f("removal_depth", s.removal_depth);
    f("record_interval", s.record_interval);
    f("frame_interval", s.frame_interval);
    f("steady_lower", s.steady_lower);
    f("steady_upper", s.steady_upper);
    f("section_cell", s.section_cell);
    f("section_half_thickness", s.section_half_thickness);
    f("wall_layer", s.flow.wall_layer);
    f("edge_clearance", s.flow.edge_clearance);
    f("axis_fraction", s.flow.axis_fraction);
    f("axis_min", s.flow.axis_min);
    f("bin_height", s.flow.bin_height);
    f("min_axis_speed", s.flow.min_axis_speed);
    f("mass_threshold", s.flow.mass_threshold);
    f("funnel_threshold", s.flow.funnel_threshold);
    f("vibration_frequency", s.vibration.frequency);
    f("vibration_amplitude", s.vibration.amplitude);
    f("vibration_direction", s.vibration.direction);
    f("vibration_start", s.vibration.start_after_opening);
    f("skin", s.skin);
    f("seed", s.seed);
    f("vtk_dir", s.vtk_dir);
    f("vtk_interval", s.vtk_interval);
    f("progress_interval", s.progress_interval);
    // since version 5 (read_settings leaves them at 0 in a version 4 checkpoint)
    f("surface_energy", s.materials.wheat_wheat.surface_energy);
    f("surface_energy", s.materials.wheat_steel.surface_energy);
    // since version 6 (keep_history before)
    f("contacts_at_opening", s.contacts_at_opening);
    // since version 7 (the whole bin before)
    f("vibration_part", s.vibration.part);
    // since version 8 (the seed's grain before)
    f("grain_aspect_ratio", s.materials.grain_aspect_ratio);
    // since version 9 (edem before)
    f("contact_law", s.contact_law);
    // since version 10 (richardson before)
    f("discharge_clump_rotation", s.discharge_clump_rotation);
    // since version 11 (exact walls before)
    f("discharge_wall_facets", s.discharge_wall_facets);
}

void write_settings(StateWriter& w, const SiloCaseSettings& s) {
    for_each_setting(s, [&](const char*, const auto& v) {
        if constexpr (std::is_same_v<std::decay_t<decltype(v)>, std::string>) w.text(v);
        else w.value(v);
    });
}

SiloCaseSettings read_settings(StateReader& r, int version) {
    SiloCaseSettings s;
    for_each_setting(s, [&](const char* name, auto& v) {
        if (version <= kCheckpointVersionWithoutCohesion && std::string_view(name) == "surface_energy") return;
        if (version <= kCheckpointVersionWithoutHistoryChoice && std::string_view(name) == "contacts_at_opening")
            return;
        if (version <= kCheckpointVersionWithoutVibratingPart && std::string_view(name) == "vibration_part") return;
        if (version <= kCheckpointVersionWithoutGrainShape && std::string_view(name) == "grain_aspect_ratio") return;
        if (version <= kCheckpointVersionWithoutLawChoice && std::string_view(name) == "contact_law") return;
        if (version <= kCheckpointVersionWithoutRotationChoice && std::string_view(name) == "discharge_clump_rotation")
            return;
        if (version <= kCheckpointVersionWithoutWallFacets && std::string_view(name) == "discharge_wall_facets") return;
        if constexpr (std::is_same_v<std::decay_t<decltype(v)>, std::string>) v = r.text(name);
        else r.value(v, name);
    });
    return s;
}

// One run of the case: generation, filling, opening, discharge; every variable that carries over from one record
// interval to the next is a member, so that a checkpoint can hold the whole run.
template <class Law>
class SiloRun {
public:
    using Progress = std::function<void(const SiloProgress&)>;

    SiloRun(const SiloCaseSettings& s, Progress progress)
        : s_(s), progress_(std::move(progress)), tmpl_(wheat_grain_template(s.materials.wheat.density, s.materials.grain_aspect_ratio)),
          grain_length_(grain_length(s.materials)) {
        validate(s_);
        sim_.set_threads(s_.threads);
        sim_.set_gravity(Vec3(0, 0, -s_.gravity));
        sim_.set_exact_removal(true);  // grains leave below the outlet all through the discharge
        wheat_ = sim_.add_material(to_kernel(s_.materials.wheat_scaled(), "wheat"));
        steel_ = sim_.add_material(to_kernel(s_.materials.steel_scaled(), "steel"));
        sim_.set_pair(wheat_, wheat_, to_kernel<Law>(s_.materials.wheat_wheat));
        sim_.set_pair(wheat_, steel_, to_kernel<Law>(s_.materials.wheat_steel));
        grain_ = sim_.add_clump_template(tmpl_);
        if (s_.vibration.vibrates()) bin_motion_ = std::make_shared<BinVibrationMotion>(s_.vibration);
        r_.grain_mass = tmpl_.mass;
        r_.cpu_sessions = 1;  // a resumed run reads the count from its checkpoint
    }

    // A new run: random sequential addition slab by slab (3 mm slabs, 30 attempts per grain volume).
    void generate() {
        const long n = s_.fill_mass > 0 ? std::max(1L, std::lround(s_.fill_mass / tmpl_.mass)) : s_.particles;
        Generator gen(s_.geometry, tmpl_, s_.seed);
        const auto placed = gen.generate(n, 0.003, 30.0);
        wall_top_ = std::max(s_.geometry.top(), gen.top() + 0.01);
        plate_ = add_silo_walls(sim_, s_.geometry, steel_, wall_top_, bin_motion_, s_.vibration.part,
                                s_.discharge_wall_facets);
        for (const auto& p : placed) sim_.add_clump(grain_, wheat_, p.com, p.q);
        r_.grains = long(placed.size());
        const double dt = s_.time_step > 0 ? s_.time_step : s_.time_step_fraction * sim_.rayleigh_timestep();
        sim_.set_timestep(dt);
        sim_.set_skin(s_.skin > 0 ? s_.skin : std::clamp(40 * dt * 1.0, 0.0002, 0.001));
        r_.time_step = dt;
        next_progress_ = progress_every();
        std::ostringstream note;
        note << "generated up to z = " << gen.top() << " m (walls to " << wall_top_ << " m), dt = " << dt
             << " s, skin " << sim_.skin() << " m";
        report("generated", note.str());
        maybe_vtk(true);
        if (s_.at_generation) s_.at_generation(bed_snapshot());
    }

    SiloCaseResult run() {
        if (phase_ == Phase::filling) {
            if (!fill()) return suspend();
            open();
        }
        if (!discharge()) return suspend();
        if (s_.at_end) s_.at_end(bed_snapshot());
        finish();
        return r_;
    }

    // ---- checkpoint
    void save(const std::string& file) {
        const std::string tmp = file + ".tmp";
        ++r_.checkpoints;
        {
            std::ofstream os(tmp, std::ios::binary | std::ios::trunc);
            if (!os) throw std::runtime_error("checkpoint '" + tmp + "': cannot open for writing");
            StateWriter head(os);
            head.text(kCheckpointTagPrefix + std::to_string(kCheckpointVersion));
            write_settings(head, s_);
            head.checksum();
            StateWriter w(os);
            w.value(phase_); w.value(wall_top_); w.value(plate_);
            w.value(lost_); w.value(next_progress_); w.value(vtk_next_step_); w.value(ke_);
            w.value(t_open_); w.value(next_frame_); w.value(mass_out_); w.value(grains_out_); w.value(last_out_time_);
            w.value(wall());
            w.value(r_.grains); w.value(r_.time_step); w.value(r_.fill_time); w.value(r_.fill_at_rest);
            w.value(r_.fill_kinetic_energy); w.value(r_.fill_height); w.value(r_.bulk_density); w.value(r_.filled_mass);
            w.value(r_.fill_steps); w.value(r_.fill_wall_s); w.value(r_.sessions); w.value(r_.checkpoints);
            w.value(r_.vtk_files);
            w.value(cpu()); w.value(r_.cpu_sessions); w.value(r_.fill_cpu_s);
            w.array(r_.discharge);
            const bool open = phase_ == Phase::discharge;
            if (open) {
                classifier_->save(w);
                r_.section->save(w);
                outlet_->save(w);
            }
            w.value(interval_steps_left_);
            w.checksum();
            sim_.save_state(os);
            os.flush();
            if (!os) throw std::runtime_error("checkpoint '" + tmp + "': write failed (disk full?)");
        }
        sync_file(tmp);
        std::error_code ec;
        std::filesystem::rename(tmp, file, ec);
        if (ec) throw std::runtime_error("checkpoint '" + file + "': cannot replace it: " + ec.message());
        last_checkpoint_wall_ = wall();
        std::ostringstream note;
        note << "checkpoint " << r_.checkpoints << " written to " << file;
        report("checkpoint", note.str());
    }

    // Restores everything save() wrote after the settings, which the caller read from the same stream (they built
    // this object).
    void load(std::istream& is, const std::string& source, int version) {
        StateReader r(is, source);
        r.value(phase_, "phase"); r.value(wall_top_, "wall top"); r.value(plate_, "plate");
        r.value(lost_, "lost grains"); r.value(next_progress_, "progress step"); r.value(vtk_next_step_, "vtk step");
        r.value(ke_, "kinetic energy"); r.value(t_open_, "opening time"); r.value(next_frame_, "frame step");
        r.value(mass_out_, "discharged mass"); r.value(grains_out_, "discharged grains");
        r.value(last_out_time_, "last discharge time"); r.value(wall_before_, "wall time");
        r.value(r_.grains, "grains"); r.value(r_.time_step, "time step"); r.value(r_.fill_time, "fill time");
        r.value(r_.fill_at_rest, "fill state"); r.value(r_.fill_kinetic_energy, "fill energy");
        r.value(r_.fill_height, "fill height"); r.value(r_.bulk_density, "bulk density");
        r.value(r_.filled_mass, "filled mass"); r.value(r_.fill_steps, "fill steps");
        r.value(r_.fill_wall_s, "fill wall time"); r.value(r_.sessions, "sessions");
        r.value(r_.checkpoints, "checkpoints"); r.value(r_.vtk_files, "vtk files");
        r.value(cpu_before_, "cpu time");
        r.value(r_.cpu_sessions, "cpu sessions");
        if (version > kCheckpointVersionWithoutFillCpu)
            r.value(r_.fill_cpu_s, "fill cpu time");
        else
            r_.fill_cpu_s = std::numeric_limits<double>::quiet_NaN();  // (set again if the filling goes on)
        r.array(r_.discharge, "discharge record");
        if (phase_ != Phase::filling && phase_ != Phase::discharge) r.fail("phase", "unknown value");
        if (bin_motion_ && phase_ == Phase::discharge) bin_motion_->open_at(t_open_);  // the law the run was on
        plate_ = add_silo_walls(sim_, s_.geometry, steel_, wall_top_, bin_motion_, s_.vibration.part,
                                s_.discharge_wall_facets);
        if (phase_ == Phase::discharge) {
            sim_.set_clump_rotation(s_.discharge_clump_rotation);
            make_discharge_recorders();
            classifier_->load(r);
            r_.section->load(r);
            // a version 6 run resumed in its discharge measures the outlet from here on (result(): its frames)
            if (version > kCheckpointVersionWithoutVibratingPart) outlet_->load(r);
        }
        interval_steps_left_ = 0;
        if (version > kCheckpointVersionWithoutIntervalStop) r.value(interval_steps_left_, "steps left of the interval");
        if (interval_steps_left_ < 0 || interval_steps_left_ >= chunk())
            r.fail("steps left of the interval", std::to_string(interval_steps_left_) + " is not within the record "
                   "interval's " + std::to_string(chunk()) + " steps");
        r.checksum();
        sim_.load_state(is, source);
        if (sim_.between_steps() != (interval_steps_left_ > 0))
            throw std::runtime_error(source + ": its kernel state " + (sim_.between_steps() ? "was" : "was not") +
                                     " stopped between two steps, its record interval says otherwise: damaged");
        ++r_.sessions;
        ++r_.cpu_sessions;
        last_checkpoint_wall_ = wall();
        std::ostringstream note;
        note << "resumed from " << source << " (session " << r_.sessions << ", checkpoint " << r_.checkpoints << ")";
        report("resumed", note.str());
    }

private:
    enum class Phase : std::int32_t { filling = 0, discharge = 1 };

    double session_wall() const {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start_).count();
    }
    double wall() const { return wall_before_ + session_wall(); }
    double cpu() const { return cpu_before_ + process_cpu_seconds() - cpu_start_; }
    // Whether this session ends here (asked after every step), and why: its wall limit, or the caller's
    // stop request. The run is then suspended with a checkpoint.
    bool session_must_end() {
        if (s_.wall_limit > 0 && session_wall() >= s_.wall_limit) {
            suspend_reason_ = "wall limit of the session (" + setting_text(s_.wall_limit) + " s) reached";
            return true;
        }
        if (s_.stop_request && !s_.checkpoint_file.empty()) {
            suspend_reason_ = s_.stop_request();
            return !suspend_reason_.empty();
        }
        return false;
    }
    long progress_every() const { return std::max(1L, std::lround(s_.progress_interval / r_.time_step)); }
    long chunk() const { return std::max(1L, std::lround(s_.record_interval / r_.time_step)); }
    // One record interval of steps, or what a stopped session left of it. The session's end (session_must_end) is
    // asked after every step, not only at the interval's end: an interval is millions of steps for a large bed (a
    // SIGTERM then waited minutes, past a batch system's grace). False: the session ends within the interval, the
    // steps left kept for the checkpoint; the next session takes them first, and the run goes on bit for bit.
    bool advance_record_interval() {
        const long todo = interval_steps_left_ > 0 ? interval_steps_left_ : chunk();
        const bool may_end = s_.wall_limit > 0 || (s_.stop_request && !s_.checkpoint_file.empty());
        const long done = may_end ? sim_.step(todo, [this] { return session_must_end(); }) : (sim_.step(todo), todo);
        interval_steps_left_ = todo - done;
        return interval_steps_left_ == 0;
    }
    bool is_below_outlet(const BodyState& b) const { return b.position.z() < -s_.removal_depth; }

    static void sync_file(const std::string& file) {
        const int fd = ::open(file.c_str(), O_RDONLY);
        if (fd >= 0) {
            ::fsync(fd);
            ::close(fd);
        }
    }

    void report(const std::string& phase, const std::string& note = "") {
        if (!progress_) return;
        pr_.phase = phase;
        pr_.time = sim_.time();
        pr_.step = sim_.steps_done();
        pr_.grains_in_silo = long(sim_.num_bodies());
        pr_.kinetic_energy_per_grain = sim_.num_bodies() ? sim_.kinetic_energy() / double(sim_.num_bodies()) : 0;
        pr_.discharge_time = phase_ == Phase::discharge ? sim_.time() - t_open_ : 0;
        pr_.grains_discharged = grains_out_;
        pr_.discharged_mass = mass_out_;
        pr_.wall_s = wall();
        pr_.step_ms = pr_.cores_busy = 0;
        if (phase == "filling" || phase == "discharge") {  // the cost of the steps since the previous such report
            const double w = session_wall(), c = process_cpu_seconds();
            if (last_report_step_ >= 0 && pr_.step > last_report_step_ && w > last_report_wall_) {
                pr_.step_ms = 1e3 * (w - last_report_wall_) / double(pr_.step - last_report_step_);
                pr_.cores_busy = (c - last_report_cpu_) / (w - last_report_wall_);
            }
            last_report_step_ = pr_.step;
            last_report_wall_ = w;
            last_report_cpu_ = c;
        }
        pr_.remaining_wall_s = 0;
        if (phase == "discharge" && pr_.step_ms > 0 && mass_out_ > 0 && pr_.discharge_time > 0) {
            const double rate = mass_out_ / pr_.discharge_time;
            const double left = std::min((s_.stop_fraction * r_.filled_mass - mass_out_) / rate,
                                         s_.max_time - pr_.discharge_time);
            pr_.remaining_wall_s = std::max(0.0, left) / r_.time_step * pr_.step_ms * 1e-3;
        }
        pr_.note = note;
        progress_(pr_);
    }

    // At the end of a record interval, once every check of the interval is done: the state is then the one the
    // next interval starts from, which is what a resumed run needs.
    // A checkpoint that cannot be written (disk full, directory removed) does not stop the run: the previous one
    // stays valid, the failure is reported and the next interval tries again.
    void maybe_checkpoint() {
        if (s_.checkpoint_file.empty() || wall() - last_checkpoint_wall_ < s_.checkpoint_interval) return;
        try {
            save(s_.checkpoint_file);
        } catch (const std::runtime_error& e) {
            --r_.checkpoints;
            last_checkpoint_wall_ = wall();
            std::error_code ec;
            std::filesystem::remove(s_.checkpoint_file + ".tmp", ec);
            report("checkpoint", std::string("NOT written, the run goes on: ") + e.what());
        }
    }

    void maybe_vtk(bool force = false) {
        if (s_.vtk_dir.empty() || (!force && sim_.steps_done() < vtk_next_step_)) return;
        SphereSnapshot snap;
        const size_t ns = sim_.num_spheres();
        for (size_t k = 0; k < ns; ++k) {
            const SphereState st = sim_.sphere(k);
            snap.positions.push_back(st.position);
            snap.velocities.push_back(st.velocity);
            snap.radii.push_back(st.radius);
            snap.clump.push_back(long(st.body));
        }
        char name[64];
        std::snprintf(name, sizeof name, "silo_%06ld.vtk", r_.vtk_files);
        write_vtk(std::filesystem::path(s_.vtk_dir) / name, snap, sim_.time());
        ++r_.vtk_files;
        vtk_next_step_ = sim_.steps_done() + std::max(1L, std::lround(s_.vtk_interval / r_.time_step));
    }

    // Filling against the closed plate until the grains are at rest (or the time limit). False: stopped at the
    // session's wall limit.
    double rest_energy() const { return s_.rest_energy_factor * tmpl_.mass * s_.gravity * grain_length_; }

    bool fill() {
        const double rest_energy = this->rest_energy();
        auto below = [this](const BodyState& b) { return is_below_outlet(b); };
        while (true) {
            if (!advance_record_interval()) return false;
            lost_ += long(sim_.remove_bodies_if(below).count);  // grains through a gap in the closed silo: none expected
            ke_ = sim_.num_bodies() ? sim_.kinetic_energy() / double(sim_.num_bodies()) : 0;
            maybe_vtk();
            if (!std::isfinite(ke_)) throw std::runtime_error("filling: the kinetic energy is not finite (unstable step?)");
            if (sim_.steps_done() >= next_progress_) {
                report("filling");
                next_progress_ += progress_every();
            }
            if (sim_.time() >= s_.fill_time_min && ke_ < rest_energy) {
                r_.fill_at_rest = true;
                break;
            }
            if (sim_.time() >= s_.fill_time_max) break;
            if (session_must_end()) return false;
            maybe_checkpoint();
        }
        r_.fill_time = sim_.time();
        r_.fill_steps = sim_.steps_done();
        r_.fill_kinetic_energy = ke_;
        r_.fill_wall_s = wall();
        r_.fill_cpu_s = cpu();
        // the filled bed: height and bulk density below 0.8 of its height
        double top = 0, mass_below = 0;
        for (size_t i = 0; i < sim_.num_bodies(); ++i) top = std::max(top, sim_.body(i).position.z());
        const double zref = 0.8 * top;
        for (size_t i = 0; i < sim_.num_bodies(); ++i) {
            const BodyState b = sim_.body(i);
            if (b.position.z() < zref) mass_below += b.mass;
        }
        r_.fill_height = top;
        r_.bulk_density = zref > 0 ? mass_below / s_.geometry.volume_below(zref) : 0;
        r_.filled_mass = sim_.total_mass();
        std::ostringstream note;
        note << (r_.fill_at_rest ? "at rest" : "time limit reached") << ", bed height " << r_.fill_height
             << " m, bulk density " << r_.bulk_density << " kg/m^3";
        if (lost_) note << ", " << lost_ << " grains lost through the closed outlet";
        report("filled", note.str());
        return true;
    }

    void make_discharge_recorders() {
        classifier_ = std::make_unique<FlowPatternClassifier>(s_.geometry, s_.flow);
        outlet_ = std::make_unique<OutletFlowMeter>(s_.geometry, tmpl_.mass);
        r_.section = std::make_shared<SectionField>(s_.geometry, s_.section_cell, s_.section_half_thickness,
                                                    r_.fill_height + 0.01);
    }

    void open() {
        if (s_.at_opening) s_.at_opening(bed_snapshot());
        if (s_.contacts_at_opening == ContactsAtOpening::forget_history) sim_.forget_contact_history();
        if (s_.contacts_at_opening == ContactsAtOpening::yade_import) sim_.restart_as_imported_leapfrog();
        sim_.set_clump_rotation(s_.discharge_clump_rotation);
        sim_.set_wall_enabled(plate_, false);
        if (s_.discharge_wall_facets > 0)  // the exact cone and cylinder give way to their facets
            for (int w = 0; w < int(sim_.num_walls()); ++w) sim_.set_wall_enabled(w, w >= silo_exact_wall_count && w != plate_);
        t_open_ = sim_.time();
        if (bin_motion_) bin_motion_->open_at(t_open_);
        make_discharge_recorders();
        next_frame_ = sim_.steps_done();
        r_.discharge.push_back({0.0, 0.0, 0});
        phase_ = Phase::discharge;
    }

    // The bed as it stands now: every grain's rigid-body state and its spheres' centres.
    BedSnapshot bed_snapshot() const {
        BedSnapshot bed;
        bed.time = sim_.time();
        bed.time_step = r_.time_step;
        bed.wall_top = wall_top_;
        bed.rest_energy = rest_energy();
        bed.grain = tmpl_;
        bed.grains.resize(sim_.num_bodies());
        for (size_t i = 0; i < sim_.num_bodies(); ++i) {
            const BodyState b = sim_.body(i);
            // BodyState's orientation is of the template frame; the principal frame is the one a rigid-body code uses
            bed.grains[i] = {b.position, (b.orientation * tmpl_.principal).normalized(), b.velocity, b.angular_velocity,
                             {}};
        }
        for (size_t k = 0; k < sim_.num_spheres(); ++k) {
            const SphereState sphere = sim_.sphere(k);
            bed.grains.at(sphere.body).spheres.push_back(sphere.position);
        }
        return bed;
    }

    // False: stopped at the session's wall limit.
    bool discharge() {
        const long frame_every = std::max(1L, std::lround(s_.frame_interval / r_.time_step));
        // a bin still to be shaken has not had its chance: the stall counts from the vibration's start at the earliest
        // (a bed arched over a closed-looking outlet stopped at 0.5 s before a vibration set to start at 0.6 s)
        const double quiet_from = s_.vibration.vibrates() ? s_.vibration.start_after_opening : 0.0;
        auto below = [this](const BodyState& b) { return is_below_outlet(b); };
        while (true) {
            if (!advance_record_interval()) return false;
            const RemovalResult rem = sim_.remove_bodies_if(below);
            mass_out_ += rem.mass;
            grains_out_ += long(rem.count);
            const double t = sim_.time() - t_open_;
            if (rem.count) last_out_time_ = t;
            r_.discharge.push_back({t, mass_out_, grains_out_});
            maybe_vtk();
            if (sim_.steps_done() >= next_frame_) {
                next_frame_ += frame_every;
                const double frac = mass_out_ / r_.filled_mass;
                if (gathers_frame(frac, s_.steady_lower, s_.steady_upper)) {  // tagged; the window is chosen at the end
                    std::vector<Eigen::Vector3d> pos, vel;
                    pos.reserve(sim_.num_bodies());
                    vel.reserve(sim_.num_bodies());
                    for (size_t i = 0; i < sim_.num_bodies(); ++i) {
                        const BodyState b = sim_.body(i);
                        pos.push_back(b.position);
                        vel.push_back(b.velocity);
                    }
                    classifier_->add_frame(pos, vel, mass_out_);
                    outlet_->add_frame(pos, vel, mass_out_);
                    if (frac >= 0.3 && frac <= 0.5) r_.section->add_frame(pos, vel);
                }
            }
            if (sim_.steps_done() >= next_progress_) {
                report("discharge");
                next_progress_ += progress_every();
            }
            if (sim_.num_bodies() == 0) {
                r_.end = DischargeEnd::emptied;
                r_.stop_reason = "empty";
                break;
            }
            if (mass_out_ >= s_.stop_fraction * r_.filled_mass * (1 - 1e-12)) {
                r_.end = DischargeEnd::stop_fraction;
                r_.stop_reason = "stop fraction " + setting_text(s_.stop_fraction) + " of the filled mass discharged";
                break;
            }
            if (FlowStallClock{quiet_from, last_out_time_}.stopped_at(t)) {
                r_.end = DischargeEnd::flow_stopped;
                r_.stop_reason = "flow stopped: no grain left for " + setting_text(kFlowStallTime) + " s, " +
                                 std::to_string(sim_.num_bodies()) + " grains remain";
                break;
            }
            if (t >= s_.max_time) {
                r_.end = DischargeEnd::time_limit;
                r_.stop_reason = "time limit " + setting_text(s_.max_time) + " s";
                break;
            }
            if (session_must_end()) return false;
            maybe_checkpoint();
        }
        return true;
    }

    // At the session's end (session_must_end): the checkpoint (it must be written: without it the session's work is
    // lost, which is reported as an error) and the state reached, marked suspended.
    SiloCaseResult suspend() {
        try {
            save(s_.checkpoint_file);
        } catch (const std::runtime_error& e) {
            throw std::runtime_error("on suspending (" + suspend_reason_ + "): " + e.what() +
                                     " (the previous checkpoint, " + std::to_string(r_.checkpoints - 1) +
                                     ", is the one to resume from)");
        }
        r_.end = DischargeEnd::suspended;
        r_.stop_reason = suspend_reason_;
        record_state();
        report("suspended", r_.stop_reason);
        return r_;
    }

    void finish() {
        maybe_vtk(true);
        // the steady part: between steady_lower and steady_upper of the mass discharged at the end
        std::vector<DischargeSample> samples;
        for (const auto& d : r_.discharge) samples.push_back({d.time, d.mass});
        r_.fit = fit_discharge_rate(samples, mass_out_, s_.steady_lower, s_.steady_upper);
        r_.flow = classifier_->result(s_.steady_lower * mass_out_, s_.steady_upper * mass_out_);
        r_.outlet = outlet_->result(s_.steady_lower * mass_out_, s_.steady_upper * mass_out_);
        record_state();
        report("done", r_.stop_reason);
    }

    // The state reached, as the result reports it: at the end of the run or at a session's wall limit.
    void record_state() {
        r_.steps = sim_.steps_done();
        r_.grains_discharged = grains_out_;
        r_.grains_in_silo = long(sim_.num_bodies());
        r_.discharge_time = phase_ == Phase::discharge ? sim_.time() - t_open_ : 0;
        r_.wall_s = wall();
        r_.cpu_s = cpu();
    }

    SiloCaseSettings s_;
    Progress progress_;
    ClumpTemplate tmpl_;
    double grain_length_;  // [m]
    BasicSimulation<Law> sim_;
    int wheat_ = 0, steel_ = 0, grain_ = 0, plate_ = -1;
    std::shared_ptr<BinVibrationMotion> bin_motion_;  // every wall's law; null: the bin is still
    SiloCaseResult r_;
    SiloProgress pr_;
    std::unique_ptr<FlowPatternClassifier> classifier_;
    std::unique_ptr<OutletFlowMeter> outlet_;
    const std::chrono::steady_clock::time_point t_start_ = std::chrono::steady_clock::now();
    double wall_before_ = 0;          // wall time of the earlier sessions of a resumed run
    const double cpu_start_ = process_cpu_seconds();
    double cpu_before_ = 0;           // CPU time of the earlier sessions that counted it
    long last_report_step_ = -1;      // the previous progress report of this session that measured the step cost
    double last_report_wall_ = 0, last_report_cpu_ = 0;
    double last_checkpoint_wall_ = 0;
    std::string suspend_reason_;      // why this session ends early (session_must_end)
    // the run's own variables, carried from one record interval to the next
    Phase phase_ = Phase::filling;
    double wall_top_ = 0;
    long lost_ = 0, next_progress_ = 0, vtk_next_step_ = 0;
    double ke_ = 0;
    double t_open_ = 0;
    long next_frame_ = 0;
    long interval_steps_left_ = 0;  // of the record interval a session stopped within (advance_record_interval)
    double mass_out_ = 0;
    long grains_out_ = 0;
    double last_out_time_ = 0;
};

std::ifstream open_checkpoint(const std::string& file) {
    std::ifstream is(file, std::ios::binary);
    if (!is) throw std::runtime_error("checkpoint '" + file + "': cannot open it (" + std::strerror(errno) + ")");
    return is;
}

// Reads the format tag and the settings; `version` receives the format version.
SiloCaseSettings settings_of(std::istream& is, const std::string& file, int& version) {
    StateReader r(is, "checkpoint '" + file + "'");
    const std::string tag = r.text("format tag");
    const std::string prefix = kCheckpointTagPrefix;
    version = 0;
    const std::string current = prefix + std::to_string(kCheckpointVersion);
    // every version from 4 on is read (the settings added since take their former values)
    for (int v = kCheckpointVersionWithoutCohesion; v <= kCheckpointVersion; ++v)
        if (tag == prefix + std::to_string(v)) version = v;
    if (version == 0 && (tag == prefix + "1" || tag == prefix + "2" || tag == prefix + "3")) {
        r.fail("format tag", "written by an older demcal (" + tag + "; this one reads " + current +
                                 "): finish that run with the demcal that started it, or start it again");
    } else if (version == 0) {
        r.fail("format tag", "'" + tag.substr(0, 40) + "' is not a silo checkpoint (" + current + ")");
    }
    SiloCaseSettings settings = read_settings(r, version);
    r.checksum();
    return settings;
}

// A new run or a resumed one (`resume` reads the state after the settings), on the law the materials ask for.
template <class Law>
SiloCaseResult run_on(const SiloCaseSettings& s, const std::function<void(const SiloProgress&)>& progress,
                      const std::function<void(SiloRun<Law>&)>& start) {
    SiloRun<Law> run(s, progress);
    start(run);
    SiloCaseResult r = run.run();
    r.contact_law = contact_law_name(s);
    return r;
}

template <class Start>
SiloCaseResult run_on_its_law(const SiloCaseSettings& s, const std::function<void(const SiloProgress&)>& progress,
                              Start&& start) {
    if (s.contact_law == SiloContactLaw::yade) return run_on<YadeHertzMindlin>(s, progress, start);
    if (s.materials.cohesive()) return run_on<JkrMindlinEdem>(s, progress, start);
    return run_on<HertzMindlinEdem>(s, progress, start);
}

}  // namespace

const std::map<std::string, SiloContactLaw>& silo_contact_laws() {
    static const std::map<std::string, SiloContactLaw> laws = {{"edem", SiloContactLaw::edem},
                                                               {"yade", SiloContactLaw::yade}};
    return laws;
}

const std::map<std::string, ClumpRotation>& silo_clump_rotations() {
    static const std::map<std::string, ClumpRotation> schemes = {{"richardson", ClumpRotation::richardson},
                                                                 {"yade", ClumpRotation::yade_leapfrog}};
    return schemes;
}

std::string silo_clump_rotation_text(ClumpRotation scheme) {
    for (const auto& [name, value] : silo_clump_rotations())
        if (value == scheme) return name;
    return "unknown (" + std::to_string(static_cast<int>(scheme)) + ")";
}

std::string silo_contact_law_text(SiloContactLaw law) {
    for (const auto& [name, value] : silo_contact_laws())
        if (value == law) return name;
    return "unknown (" + std::to_string(static_cast<int>(law)) + ")";
}

std::string contact_law_name(const SiloCaseSettings& s) {
    if (s.contact_law == SiloContactLaw::yade)
        return "YADE's Hertz-Mindlin (incremental tangential force, normal force clipped at zero), no rolling friction";
    return s.materials.cohesive() ? "Hertz-Mindlin with JKR cohesion, EDEM rolling friction"
                                  : "Hertz-Mindlin (no slip), EDEM rolling friction";
}

SiloCaseResult run_silo_case(const SiloCaseSettings& s, const std::function<void(const SiloProgress&)>& progress) {
    return run_on_its_law(s, progress, [](auto& run) { run.generate(); });
}

SiloCaseSettings read_checkpoint_settings(const std::string& file) {
    std::ifstream is = open_checkpoint(file);
    int version = 0;
    return settings_of(is, file, version);
}

SiloCaseResult resume_silo_case(const std::string& file, const SiloSession& session,
                                const std::function<void(const SiloProgress&)>& progress) {
    std::ifstream is = open_checkpoint(file);
    int version = 0;
    SiloCaseSettings s = settings_of(is, file, version);
    s.threads = session.threads;
    s.checkpoint_file = file;
    s.checkpoint_interval = session.checkpoint_interval;
    s.wall_limit = session.wall_limit;
    s.stop_request = session.stop_request;
    return run_on_its_law(s, progress, [&](auto& run) {
        try {
            run.load(is, "checkpoint '" + file + "'", version);
        } catch (const std::runtime_error& e) {  // a damaged or foreign file is bad input, wherever the damage lies
            throw std::invalid_argument(e.what());
        }
        // the checksums cover what was read: bytes after the end are a file appended to or pasted together
        if (is.peek() != std::char_traits<char>::eof())
            throw std::invalid_argument("checkpoint '" + file + "': bytes after its end (the file was appended to or "
                                        "damaged); refused");
    });
}

}  // namespace demcal::kernel::silo
