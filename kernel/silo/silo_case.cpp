#include "kernel/silo/silo_case.hpp"
#include "kernel/silo/input_error.hpp"

#include "kernel/clump.hpp"
#include "kernel/simulation.hpp"
#include "kernel/walls.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <random>
#include <sstream>
#include <stdexcept>
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

kernel::PairProperties to_kernel(const PairCoefficients& p) {
    kernel::PairProperties k;
    k.restitution = p.restitution;
    k.friction = p.friction;
    k.rolling_friction = p.rolling_friction;
    return k;
}

// The silo's walls; returns the outlet plate's wall id. The body wall reaches up to `wall_top`.
int add_silo_walls(Simulation& sim, const SiloGeometry& g, int steel, double wall_top) {
    const double hh = g.hopper_height(), th = g.half_angle_deg * pi / 180;
    if (g.shape == SiloShape::conical) {
        const double r0 = g.outlet_half(), R = g.top_half();
        sim.add_wall(Wall::cone(0, 0, r0, 0, th, R, steel));
        sim.add_wall(Wall::cylinder(0, 0, R, hh, wall_top, steel));
        return sim.add_wall(Wall::disk(0, 0, r0 * 1.001, 0, steel));
    }
    const double a2 = 0.5 * g.outlet, b2 = 0.5 * g.depth, c2 = 0.5 * g.width;
    for (double s : {-1.0, 1.0}) {
        // slanted hopper wall from the outlet edge (x = s a/2, z = 0) to the body (x = s c/2, z = hh), full depth
        sim.add_wall(Wall::rectangle_from_corners(Vec3(s * a2, -b2, 0), Vec3(s * a2, b2, 0), Vec3(s * c2, -b2, hh),
                                                  steel));
        // vertical body wall x = s c/2
        sim.add_wall(Wall::rectangle_from_corners(Vec3(s * c2, -b2, hh), Vec3(s * c2, b2, hh),
                                                  Vec3(s * c2, -b2, wall_top), steel));
        // front/back wall y = s b/2 over the whole height (the part outside the hopper is never reached)
        sim.add_wall(Wall::rectangle_from_corners(Vec3(-c2, s * b2, 0), Vec3(c2, s * b2, 0), Vec3(-c2, s * b2, wall_top),
                                                  steel));
    }
    return sim.add_wall(Wall::rectangle(Vec3(0, 0, 0), Vec3::UnitZ(), Vec3::UnitX(), a2 * 1.001, b2, steel));
}

}  // namespace

void validate(const SiloCaseSettings& s) {
    validate(s.geometry, wheat_length);
    if (s.fill_mass < 0 || !std::isfinite(s.fill_mass)) reject_setting("fill_mass", s.fill_mass, "must be >= 0 kg");
    if (s.fill_mass == 0 && s.particles < 1) reject_setting("particles", double(s.particles), "must be at least 1");
    if (s.particles > 5000000) reject_setting("particles", double(s.particles), "more than 5,000,000 grains");
    if (!(s.materials.stiffness_scale > 0) || s.materials.stiffness_scale > 100)
        reject_setting("stiffness_scale", s.materials.stiffness_scale, "must lie in (0, 100]");
    if (s.time_step < 0 || !std::isfinite(s.time_step)) reject_setting("dt", s.time_step, "must be >= 0 s (0: automatic)");
    if (!(s.time_step_fraction > 0 && s.time_step_fraction <= 1))
        reject_setting("dt_fraction", s.time_step_fraction, "must lie in (0, 1] (of the Rayleigh time step)");
    if (!(s.fill_time_max > 0) || !std::isfinite(s.fill_time_max)) reject_setting("fill_time", s.fill_time_max, "must be > 0 s");
    if (!(s.max_time > 0) || !std::isfinite(s.max_time)) reject_setting("max_time", s.max_time, "must be > 0 s");
    if (!(s.stop_fraction > 0 && s.stop_fraction <= 1))
        reject_setting("stop_fraction", s.stop_fraction, "must lie in (0, 1]");
    if (!(s.threads >= 1)) reject_setting("threads", s.threads, "must be at least 1");
    if (!(s.skin >= 0) || s.skin > 0.01) reject_setting("skin", s.skin, "must lie in [0, 0.01] m (0: automatic)");
    if (!s.vtk_dir.empty() && !(s.vtk_interval > 0)) reject_setting("vtk_every", s.vtk_interval, "must be > 0 s");
    if (!(s.record_interval > 0)) reject_setting("record_interval", s.record_interval, "must be > 0 s");
    if (!(s.steady_lower >= 0 && s.steady_lower < s.steady_upper && s.steady_upper <= 1))
        reject_setting("steady_lower", s.steady_lower, "the steady window must satisfy 0 <= lower < upper <= 1");
}

SiloCaseResult run_silo_case(const SiloCaseSettings& s, const std::function<void(const SiloProgress&)>& progress) {
    validate(s);
    using clock = std::chrono::steady_clock;
    const auto t_start = clock::now();
    auto wall = [&] { return std::chrono::duration<double>(clock::now() - t_start).count(); };
    const SiloGeometry& g = s.geometry;

    Simulation sim;
    sim.set_threads(s.threads);
    sim.set_gravity(Vec3(0, 0, -s.gravity));
    const int wheat = sim.add_material(to_kernel(s.materials.wheat_scaled(), "wheat"));
    const int steel = sim.add_material(to_kernel(s.materials.steel_scaled(), "steel"));
    sim.set_pair(wheat, wheat, to_kernel(s.materials.wheat_wheat));
    sim.set_pair(wheat, steel, to_kernel(s.materials.wheat_steel));
    const ClumpTemplate tmpl = wheat_clump_template(s.materials.wheat.density);
    const int grain = sim.add_clump_template(tmpl);

    SiloCaseResult r;
    r.grain_mass = tmpl.mass;
    const long n = s.fill_mass > 0 ? std::max(1L, std::lround(s.fill_mass / tmpl.mass)) : s.particles;

    // ---- generation: random sequential addition slab by slab (3 mm slabs, 30 attempts per grain volume)
    Generator gen(g, tmpl, s.seed);
    const auto placed = gen.generate(n, 0.003, 30.0);
    const double wall_top = std::max(g.top(), gen.top() + 0.01);
    const int plate = add_silo_walls(sim, g, steel, wall_top);
    for (const auto& p : placed) sim.add_clump(grain, wheat, p.com, p.q);
    r.grains = long(placed.size());
    const double dt = s.time_step > 0 ? s.time_step : s.time_step_fraction * sim.rayleigh_timestep();
    sim.set_timestep(dt);
    sim.set_skin(s.skin > 0 ? s.skin : std::clamp(40 * dt * 1.0, 0.0002, 0.001));
    r.time_step = dt;

    SiloProgress pr;
    auto report = [&](const std::string& phase, const std::string& note = "") {
        if (!progress) return;
        pr.phase = phase;
        pr.time = sim.time();
        pr.step = sim.steps_done();
        pr.grains_in_silo = long(sim.num_bodies());
        pr.kinetic_energy_per_grain = sim.num_bodies() ? sim.kinetic_energy() / double(sim.num_bodies()) : 0;
        pr.wall_s = wall();
        pr.note = note;
        progress(pr);
    };
    {
        std::ostringstream note;
        note << "generated up to z = " << gen.top() << " m (walls to " << wall_top << " m), dt = " << dt
             << " s, skin " << sim.skin() << " m";
        report("generated", note.str());
    }

    // ---- VTK
    long vtk_next_step = 0;
    const long vtk_every = s.vtk_dir.empty() ? 0 : std::max(1L, std::lround(s.vtk_interval / dt));
    auto maybe_vtk = [&](bool force = false) {
        if (s.vtk_dir.empty() || (!force && sim.steps_done() < vtk_next_step)) return;
        SphereSnapshot snap;
        const size_t ns = sim.num_spheres();
        for (size_t k = 0; k < ns; ++k) {
            const SphereState st = sim.sphere(k);
            snap.positions.push_back(st.position);
            snap.velocities.push_back(st.velocity);
            snap.radii.push_back(st.radius);
            snap.clump.push_back(long(st.body));
        }
        char name[64];
        std::snprintf(name, sizeof name, "silo_%06ld.vtk", r.vtk_files);
        write_vtk(std::filesystem::path(s.vtk_dir) / name, snap, sim.time());
        ++r.vtk_files;
        vtk_next_step = sim.steps_done() + vtk_every;
    };

    // ---- filling against the closed plate
    const double rest_energy = s.rest_energy_factor * tmpl.mass * s.gravity * wheat_length;
    const long chunk = std::max(1L, std::lround(s.record_interval / dt));
    const long progress_every = std::max(1L, std::lround(s.progress_interval / dt));
    long next_progress = progress_every;
    long lost = 0;
    auto below = [&](const BodyState& b) { return b.position.z() < -s.removal_depth; };
    maybe_vtk(true);
    double ke = 0;
    while (true) {
        sim.step(chunk);
        lost += long(sim.remove_bodies_if(below).count);  // grains through a gap in the closed silo: none expected
        ke = sim.num_bodies() ? sim.kinetic_energy() / double(sim.num_bodies()) : 0;
        maybe_vtk();
        if (!std::isfinite(ke)) throw std::runtime_error("filling: the kinetic energy is not finite (unstable step?)");
        if (sim.steps_done() >= next_progress) {
            report("filling");
            next_progress += progress_every;
        }
        if (sim.time() >= s.fill_time_min && ke < rest_energy) {
            r.fill_at_rest = true;
            break;
        }
        if (sim.time() >= s.fill_time_max) break;
    }
    r.fill_time = sim.time();
    r.fill_steps = sim.steps_done();
    r.fill_kinetic_energy = ke;
    r.fill_wall_s = wall();
    // the filled bed: height and bulk density below 0.8 of its height
    {
        double top = 0, mass_below = 0;
        for (size_t i = 0; i < sim.num_bodies(); ++i) top = std::max(top, sim.body(i).position.z());
        const double zref = 0.8 * top;
        for (size_t i = 0; i < sim.num_bodies(); ++i) {
            const BodyState b = sim.body(i);
            if (b.position.z() < zref) mass_below += b.mass;
        }
        r.fill_height = top;
        r.bulk_density = zref > 0 ? mass_below / g.volume_below(zref) : 0;
    }
    const long filled_grains = long(sim.num_bodies());
    r.filled_mass = sim.total_mass();
    {
        std::ostringstream note;
        note << (r.fill_at_rest ? "at rest" : "time limit reached") << ", bed height " << r.fill_height
             << " m, bulk density " << r.bulk_density << " kg/m^3";
        if (lost) note << ", " << lost << " grains lost through the closed outlet";
        report("filled", note.str());
    }

    // ---- discharge
    sim.set_wall_enabled(plate, false);
    const double t_open = sim.time();
    const long open_step = sim.steps_done();
    FlowPatternClassifier classifier(g, s.flow);
    r.section = std::make_shared<SectionField>(g, s.section_cell, s.section_half_thickness, r.fill_height + 0.01);
    const long frame_every = std::max(1L, std::lround(s.frame_interval / dt));
    long next_frame = sim.steps_done();
    double mass_out = 0;
    long grains_out = 0;
    r.discharge.push_back({0.0, 0.0, 0});
    double last_out_time = 0;
    const double stall_time = 0.5;  // no grain discharged for this long with grains left: the flow has stopped
    while (true) {
        sim.step(chunk);
        const RemovalResult rem = sim.remove_bodies_if(below);
        mass_out += rem.mass;
        grains_out += long(rem.count);
        const double t = sim.time() - t_open;
        if (rem.count) last_out_time = t;
        r.discharge.push_back({t, mass_out, grains_out});
        maybe_vtk();
        if (sim.steps_done() >= next_frame) {
            next_frame += frame_every;
            const double frac = mass_out / r.filled_mass;
            if (frac >= s.steady_lower * 0.5 && frac <= s.steady_upper) {  // tagged; the window is chosen at the end
                std::vector<Eigen::Vector3d> pos, vel;
                pos.reserve(sim.num_bodies());
                vel.reserve(sim.num_bodies());
                for (size_t i = 0; i < sim.num_bodies(); ++i) {
                    const BodyState b = sim.body(i);
                    pos.push_back(b.position);
                    vel.push_back(b.velocity);
                }
                classifier.add_frame(pos, vel, mass_out);
                if (frac >= 0.3 && frac <= 0.5) r.section->add_frame(pos, vel);
            }
        }
        pr.discharge_time = t;
        pr.grains_discharged = grains_out;
        pr.discharged_mass = mass_out;
        if (sim.steps_done() >= next_progress) {
            report("discharge");
            next_progress += progress_every;
        }
        if (sim.num_bodies() == 0) {
            r.emptied = true;
            r.stop_reason = "empty";
            break;
        }
        if (mass_out >= s.stop_fraction * r.filled_mass * (1 - 1e-12)) {
            r.stop_reason = "stop fraction " + setting_text(s.stop_fraction) + " of the filled mass discharged";
            break;
        }
        if (t - last_out_time > stall_time) {
            r.stop_reason = "flow stopped: no grain left for " + setting_text(stall_time) + " s, " +
                            std::to_string(sim.num_bodies()) + " grains remain";
            break;
        }
        if (t >= s.max_time) {
            r.stop_reason = "time limit " + setting_text(s.max_time) + " s";
            break;
        }
    }
    maybe_vtk(true);
    r.discharge_time = sim.time() - t_open;
    r.grains_discharged = grains_out;
    r.grains_in_silo = long(sim.num_bodies());
    r.steps = sim.steps_done();
    (void)open_step;
    (void)filled_grains;
    // the steady part: between steady_lower and steady_upper of the mass discharged at the end
    std::vector<DischargeSample> samples;
    for (const auto& d : r.discharge) samples.push_back({d.time, d.mass});
    r.fit = fit_discharge_rate(samples, mass_out, s.steady_lower, s.steady_upper);
    r.flow = classifier.result(s.steady_lower * mass_out, s.steady_upper * mass_out);
    r.wall_s = wall();
    report("done", r.stop_reason);
    return r;
}

}  // namespace demcal::kernel::silo
