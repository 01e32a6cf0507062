#include "app/crosscheck_silo_report.hpp"

#include "app/gnuplot.hpp"
#include "app/result_files.hpp"
#include "app/silo_flow_pattern.hpp"
#include "analytics/user_input.hpp"
#include "kernel/silo/silo_geometry.hpp"
#include "orchestrator/run_identity.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>

namespace demcal::crosscheck_silo {

namespace fs = std::filesystem;
using nlohmann::json;

std::string theta_name(double theta) {
    std::ostringstream o;
    o << "theta_" << theta;
    return o.str();
}

std::string angle_folder(double theta, kernel::silo::SiloContactLaw law) {
    if (law == kernel::silo::SiloContactLaw::edem) return theta_name(theta);
    return theta_name(theta) + "_law-" + kernel::silo::silo_contact_law_text(law);
}

std::string kernel_folder(kernel::ClumpRotation rotation, int wall_facets, bool start_as_yade_import) {
    std::string folder = "kernel";
    if (rotation != kernel::ClumpRotation::richardson)
        folder += "-rotation-" + kernel::silo::silo_clump_rotation_text(rotation);
    if (wall_facets > 0) folder += "-facets-" + std::to_string(wall_facets);
    if (start_as_yade_import) folder += "-yade-import";
    return folder;
}

namespace {

// The differences between the two codes' set-ups that YADE cannot remove (yade_scripts/README.md measures them): those
// of the kernel's own contact law, gone when it runs YADE's (--kernel-law yade), and those left on either law.
const char* const kOwnLawDifferences[] = {
    "rolling friction: YADE has no EDEM-type constant directional torque; its elastic-plastic rolling moment "
    "(run.rolling_moment) is a different law (measured on a 30 deg bed: +2.6 % on the rate against none). YADE runs "
    "without rolling resistance by default: at 10 deg (4000 grains) YADE / kernel was 1.064 and 1.087 on two beds; "
    "with rolling friction 0 in both codes 1.032, 0.989, 1.019, 0.994 at 10, 30, 50, 70 deg "
    "(examples/crosscheck/README.md)",
    "tangential spring: YADE's Mindlin law is incremental, the kernel's a rotated history spring (same stiffness); "
    "YADE starts the imported bed's contacts afresh, without the kernel's springs (the kernel forgetting its own at "
    "the opening, demcal silo --forget-contact-history, moved its rate by -2.8 to +2.1 %, no systematic sign)",
    "YADE clips the normal force at zero in a separating contact; the kernel does not (a very small effect at "
    "restitution 0.5-0.6)",
};
const char* const kYadeLawDifferences[] = {
    "contact law: the kernel runs YADE 2023.02a's Hertz-Mindlin (kernel/contact/yade_mindlin_*.hpp, equal to YADE's "
    "own single-contact traces to 1e-6, two spheres and a sphere on a hertzian facet)",
};
const char* const kKeptHistoryDifference =
    "contact history at the opening: YADE starts the imported bed's contacts afresh (tangential forces at zero), the "
    "kernel keeps its own (--kernel-start-as-yade-import starts it as YADE does)";
const char* const kYadeImportStart =
    "start: the kernel starts the discharge as YADE's import of the bed does (--kernel-start-as-yade-import: contacts "
    "afresh, their springs advanced in the first force evaluation, a whole first kick); with YADE's law, rotation and "
    "walls the two codes then follow one trajectory (4000 grains: 1e-9 of the displacement after 150 steps) until "
    "chaos parts them";
const char* const kOwnRotationDifference =
    "integrators: YADE's leapfrog with its aspherical rotation for clumps, the kernel's velocity Verlet with a "
    "Richardson quaternion update (--kernel-rotation yade discharges with YADE's rotation instead)";
const char* const kYadeRotationDifference =
    "integrators: the kernel discharges with YADE's aspherical clump rotation (--kernel-rotation yade; it follows "
    "YADE's own trace of a spinning clump to rounding); velocity Verlet and YADE's leapfrog step positions alike";
const char* const kExactWallsDifference =
    "walls: YADE's cone and cylinder are facet polygons (72 sides), the kernel's are exact surfaces of revolution "
    "(--wall-facets N runs both on N facets)";

std::vector<std::string> known_differences(const ReportSettings& s) {
    const bool yade_law = s.kernel_law == kernel::silo::SiloContactLaw::yade;
    std::vector<std::string> d(yade_law ? std::begin(kYadeLawDifferences) : std::begin(kOwnLawDifferences),
                               yade_law ? std::end(kYadeLawDifferences) : std::end(kOwnLawDifferences));
    if (yade_law) d.push_back(s.start_as_yade_import ? kYadeImportStart : kKeptHistoryDifference);
    d.push_back(s.kernel_rotation == kernel::ClumpRotation::yade_leapfrog ? kYadeRotationDifference
                                                                          : kOwnRotationDifference);
    d.push_back(s.wall_facets > 0 ? "walls: the same " + std::to_string(s.wall_facets) +
                                        "-sided facet polygons in both codes from the opening on (--wall-facets; the "
                                        "kernel's facet contact follows YADE's own trace across a facet's edges and "
                                        "vertices to 1e-6); the kernel fills on exact walls, so the bed is the same"
                                  : std::string(kExactWallsDifference));
    return d;
}

std::string g(double v, int digits = 4) {
    std::ostringstream o;
    o << std::setprecision(digits) << v;
    return o.str();
}

// ---- mass-time curves ----

struct CurvePoint {
    double t, mass;
};
using Curve = std::vector<CurvePoint>;

Curve kernel_curve(const fs::path& csv) {
    Curve c;
    std::ifstream f(csv);
    std::string line;
    std::getline(f, line);  // header
    while (std::getline(f, line)) {
        std::istringstream s(line);
        double t = 0, m = 0;
        char comma = 0;
        if (s >> t >> comma >> m) c.push_back({t, m});
    }
    return c;
}

Curve yade_curve(const json& result) {
    Curve c;
    const auto& t = result.at("curve").at("time_s");
    const auto& m = result.at("curve").at("discharged_mass_kg");
    for (std::size_t i = 0; i < t.size(); ++i) c.push_back({t[i].get<double>(), m[i].get<double>()});
    return c;
}

double mass_at(const Curve& c, double t) {
    if (c.empty()) return 0;
    if (t <= c.front().t) return c.front().mass;
    if (t >= c.back().t) return c.back().mass;
    const auto it = std::lower_bound(c.begin(), c.end(), t, [](const CurvePoint& p, double x) { return p.t < x; });
    const CurvePoint& b = *it;
    const CurvePoint& a = *(it - 1);
    return a.mass + (b.mass - a.mass) * (t - a.t) / (b.t - a.t);
}

// The largest gap between the curves at the kernel's recorded times, as a fraction of the filled mass.
double largest_gap(const Curve& k, const Curve& y, double filled) {
    double gap = 0;
    const double t_end = std::min(k.empty() ? 0 : k.back().t, y.empty() ? 0 : y.back().t);
    for (const auto& p : k)
        if (p.t <= t_end) gap = std::max(gap, std::abs(p.mass - mass_at(y, p.t)));
    return filled > 0 ? gap / filled : 0;
}

void write_curve_data(const fs::path& file, const Curve& c) {
    std::ostringstream f;
    for (const auto& p : c) f << p.t << " " << p.mass * 1e3 << "\n";
    write_result_file(file, f.str());
}

// `own`: YADE's discharge of the bed it filled itself (--fill both), drawn when not empty.
void write_curve_plot(const fs::path& dir, double theta, const Curve& k, const Curve& y, const Curve& own,
                      const std::string& format) {
    const fs::path data_k = dir / "curve_kernel.dat", data_y = dir / "curve_yade.dat",
                   data_own = dir / "curve_yade_own_fill.dat";
    write_curve_data(data_k, k);
    write_curve_data(data_y, y);
    if (!own.empty()) write_curve_data(data_own, own);
    std::ostringstream s;
    s << "set title 'Discharged mass, cone half angle " << theta << " deg'\n"
      << "set xlabel 'time since opening [s]'\nset ylabel 'discharged mass [g]'\nset key top left\nset grid\n"
      << "plot " << gnuplot_quote(data_k) << " using 1:2 with lines lw 2 title 'demcal kernel', "
      << gnuplot_quote(data_y) << " using 1:2 with lines lw 2 dt 2 title 'YADE 2023.02a'";
    if (!own.empty())
        s << ", " << gnuplot_quote(data_own) << " using 1:2 with lines lw 2 dt 3 title 'YADE, its own filling'";
    s << "\n";
    render_gnuplot(dir / ("mass_time." + format), s.str());
}

// ---- one angle's runs ----

// YADE's flow pattern: its frames through the kernel's classifier with the kernel's sampling (from the bed).
json yade_flow_pattern(const fs::path& dir, const json& bed, const json& yade_result) {  // dir: the YADE run's
    try {
        const FlowPatternSampling sampling =
            flow_pattern_sampling_from_json(bed.at("flow_pattern_sampling"), "bed of " + dir.string());
        const json& geometry = bed.at("geometry");
        const auto silo = kernel::silo::SiloGeometry::conical(
            geometry.at("theta_deg").get<double>(), geometry.at("outlet_m").get<double>(),
            geometry.at("D_m").get<double>(), geometry.at("body_height_m").get<double>());
        return flow_pattern_json(flow_pattern_of_frames(dir / kYadeFramesFile, silo, sampling,
                                                        yade_result.at("initial_mass_kg").get<double>(),
                                                        yade_result.at("discharged_mass_kg").get<double>()));
    } catch (const std::exception& e) {
        return {{"pattern", "undetermined"}, {"wall_to_axis_velocity_ratio", 0.0}, {"message", e.what()}};
    }
}

struct KernelSide {
    json summary;  // demcal silo's summary.json
    double rate = 0, filled = 0, cpu = 0;
    double discharge_cpu = 0;  // the part of cpu after the opening (NaN: unknown), YADE's share of the work
    Curve curve;
};

KernelSide read_kernel_side(const fs::path& kernel_dir) {
    KernelSide k;
    k.summary = orchestrator::read_result_json(kernel_dir / "summary.json",
                                               "kernel summary '" + (kernel_dir / "summary.json").string() + "'");
    // (no rate where the run could not determine one: nothing discharged, no steady window)
    k.rate = k.summary.at("rate").value("rate_kg_s", std::numeric_limits<double>::quiet_NaN());
    k.filled = k.summary.at("filled_mass_kg").get<double>();
    k.cpu = k.summary.at("cpu_s").get<double>();
    const json& discharge_cpu = k.summary.at("discharge").value("cpu_s", json(nullptr));  // (summaries before it: none)
    k.discharge_cpu = discharge_cpu.is_number() ? discharge_cpu.get<double>() : std::numeric_limits<double>::quiet_NaN();
    k.curve = kernel_curve(kernel_dir / "discharge.csv");
    return k;
}

struct YadeSide {
    json result;  // silo.py's result.json
    double rate = 0, cpu = 0;
    Curve curve;
    json pattern;
};

YadeSide read_yade_side(const fs::path& angle_dir, const YadeRunKind& kind) {
    YadeSide y;
    y.result = analytics::read_json_input(angle_dir / kind.folder / "result.json",
                                          kind.fills ? "yade own-fill result" : "yade result");
    y.rate = y.result.at("rate").value("rate_kg_s", std::numeric_limits<double>::quiet_NaN());
    y.cpu = y.result.at("cpu_time_s").get<double>();
    y.curve = yade_curve(y.result);
    y.pattern = yade_flow_pattern(angle_dir / kind.folder,
                                  analytics::read_json_input(angle_dir / kind.bed_file, kind.fills ? "cloud" : "bed"),
                                  y.result);
    return y;
}

// The kernel's and one YADE run's discharge of an angle, compared.
struct Comparison {
    double theta = 0;
    double ratio = 0;  // YADE / kernel rate
    double gap = 0;    // largest gap between the curves, fraction of the filled mass
    bool agree = false;
    bool patterns_determined = false;  // both codes determined a pattern (too few grains may leave one undetermined)
    bool patterns_agree = false;
};

Comparison compare(double theta, const KernelSide& k, const YadeSide& y, double tolerance) {
    Comparison c;
    c.theta = theta;
    c.ratio = y.rate / k.rate;
    c.gap = largest_gap(k.curve, y.curve, k.filled);
    c.agree = std::abs(c.ratio - 1) <= tolerance;
    const json& pattern = k.summary.at("flow_pattern");
    c.patterns_determined = pattern.value("pattern", "undetermined") != "undetermined" &&
                            y.pattern.value("pattern", "undetermined") != "undetermined";
    c.patterns_agree = c.patterns_determined && pattern.value("pattern", "") == y.pattern.value("pattern", "");
    return c;
}

// A number that may be unknown (NaN): formatted, or "-" in a table and null in JSON.
std::string known_or_dash(double x, int digits) { return std::isfinite(x) ? g(x, digits) : "-"; }
json known_or_null(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

std::string pattern_cell(const json& pattern) {
    return pattern.value("pattern", "?") + " (" + g(pattern.value("wall_to_axis_velocity_ratio", 0.0), 2) + ")";
}

std::string comparison_row(const Comparison& c, const KernelSide& k, const YadeSide& y) {
    const bool marked = c.patterns_determined && !c.patterns_agree;
    std::ostringstream md;
    md << "| " << c.theta << " | " << g(k.rate * 1e3) << " ("
       << g(k.summary["rate"].value("rate_batch_se_kg_s", 0.0) * 1e3, 2) << ") | " << g(y.rate * 1e3) << " ("
       << g(y.result["rate"].value("rate_se_kg_s", 0.0) * 1e3, 2) << ") | " << g(c.ratio, 4) << " | "
       << (c.agree ? "agree" : "**DIFFER**") << " | " << g(k.summary.at("discharge").at("time_s").get<double>(), 3)
       << " | " << g(y.result.at("discharge_time_s").get<double>(), 3) << " | "
       << pattern_cell(k.summary.at("flow_pattern")) << " | " << (marked ? "**" : "") << pattern_cell(y.pattern)
       << (marked ? "**" : "") << " | " << g(100 * c.gap, 2) << " | " << g(k.cpu, 3) << " ("
       << known_or_dash(k.discharge_cpu, 3) << ") | " << g(y.cpu, 3) << " | "
       << known_or_dash(y.cpu / k.discharge_cpu, 3) << " (" << g(y.cpu / k.cpu, 3) << ") |\n";
    return md.str();
}

json comparison_json(const Comparison& c, const KernelSide& k, const YadeSide& y, const YadeRunKind& kind) {
    return {{"theta_deg", c.theta},
            {"kernel", {{"rate_kg_s", k.rate},
                        {"rate_batch_se_kg_s", k.summary["rate"].value("rate_batch_se_kg_s", 0.0)},
                        {"time_to_empty_s", k.summary.at("discharge").at("time_s")},
                        {"flow_pattern", k.summary.at("flow_pattern")},
                        {"cpu_s", k.cpu},
                        {"discharge_cpu_s", known_or_null(k.discharge_cpu)},
                        {"wall_s", k.summary.at("wall_s")}}},
            {"yade", {{"rate_kg_s", y.rate},
                      {"rate_se_kg_s", y.result["rate"].value("rate_se_kg_s", 0.0)},
                      {"time_to_empty_s", y.result.at("discharge_time_s")},
                      {"stop_reason", y.result.at("stop_reason")},
                      {"flow_pattern", y.pattern},
                      {"cpu_s", y.cpu},
                      {"wall_s", y.result.at("wall_time_s")},
                      {"started_from", kind.label}}},
            {"rate_ratio_yade_over_kernel", c.ratio},
            {"rates_agree", c.agree},
            {"patterns_agree", c.patterns_determined ? json(c.patterns_agree) : json(nullptr)},
            {"yade_material_as_bed", y.result.value("material_as_bed", true)},
            {"largest_curve_gap_of_filled_mass", c.gap},
            {"cpu_ratio_yade_over_kernel", y.cpu / k.cpu},  // YADE's discharge over the kernel's fill and discharge
            {"discharge_cpu_ratio_yade_over_kernel", known_or_null(y.cpu / k.discharge_cpu)}};
}

// --fill both: YADE's discharge of the bed it filled itself, beside the same-bed ratio. The filling's share of the
// rate difference is what YADE's own bed adds to the ratio of the same bed.
double filling_share(const KernelSide& k, const YadeSide& own, const Comparison& same_bed) {
    return own.rate / k.rate - same_bed.ratio;
}

std::string own_fill_row(const Comparison& same_bed, const KernelSide& k, const YadeSide& own) {
    const json& yf = own.result.at("fill");
    const json& kf = k.summary.at("fill");
    std::ostringstream md;
    md << "| " << same_bed.theta << " | " << g(k.rate * 1e3) << " | " << g(own.rate * 1e3) << " | "
       << g(own.rate / k.rate, 4) << " | " << g(same_bed.ratio, 4) << " | " << std::showpos
       << g(100 * filling_share(k, own, same_bed), 2) << std::noshowpos << " | "
       << g(kf.at("time_s").get<double>(), 3) << " / " << g(yf.at("time_s").get<double>(), 3) << " | "
       << g(kf.at("height_m").get<double>() * 1e3, 4) << " / " << g(yf.at("bed_height_m").get<double>() * 1e3, 4)
       << " | " << pattern_cell(own.pattern) << " | " << g(own.cpu, 3) << " |\n";
    return md.str();
}

json own_fill_json(const Comparison& same_bed, const KernelSide& k, const YadeSide& own) {
    return {{"rate_kg_s", own.rate},
            {"rate_ratio_yade_over_kernel", own.rate / k.rate},
            {"filling_share_of_rate_ratio", filling_share(k, own, same_bed)},
            {"fill", own.result.at("fill")},
            {"kernel_fill", k.summary.at("fill")},
            {"time_to_empty_s", own.result.at("discharge_time_s")},
            {"flow_pattern", own.pattern},
            {"cpu_s", own.result.at("cpu_time_s")},
            {"largest_curve_gap_of_filled_mass", largest_gap(k.curve, own.curve, k.filled)}};
}

// ---- the whole report ----

constexpr const char* kComparisonHeader =
    "| theta [deg] | kernel rate [g/s] (batch SE) | YADE rate [g/s] (slope SE) | YADE / kernel | rates | kernel empty "
    "[s] | YADE empty [s] | kernel pattern (wall/axis) | YADE pattern (wall/axis) | largest curve gap [% of fill] | "
    "kernel CPU [s]: fill + discharge (discharge) | YADE CPU [s] (discharge) | YADE / kernel CPU: discharge (whole "
    "kernel run) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";

constexpr const char* kOwnFillSection =
    "\n## Each code fills on its own\n\nYADE fills the silo itself from the kernel's generated cloud (the same "
    "grains, positions and orientations before the first filling step; the kernel's rest rule), then discharges. The "
    "filling's share of the difference is YADE's own-fill rate over the kernel's minus the same-bed ratio.\n\n| theta "
    "[deg] | kernel rate [g/s] | YADE own fill [g/s] | YADE own fill / kernel | YADE same bed / kernel | filling's "
    "share [% of the kernel's rate] | fill time kernel / YADE [s] | bed height kernel / YADE [mm] | YADE own fill "
    "pattern (wall/axis) | YADE own fill CPU [s] |\n|---|---|---|---|---|---|---|---|---|---|\n";

// What holds over all angles, for the closing lines.
struct Verdict {
    bool all_agree = true, all_patterns_agree = true, all_patterns_determined = true;
    std::size_t compared = 0;  // angles at which both codes' runs are there: the verdicts hold over these only
    void add(const Comparison& c) {
        ++compared;
        all_agree = all_agree && c.agree;
        all_patterns_agree = all_patterns_agree && (c.patterns_agree || !c.patterns_determined);
        all_patterns_determined = all_patterns_determined && c.patterns_determined;
    }
};

std::string closing_text(const ReportSettings& s, const Verdict& v) {
    if (v.compared == 0)
        return "\nNo angle could be compared: a run of every angle failed (see the rows above); nothing is concluded.\n";
    const std::string at_every = v.compared == s.thetas.size()
                                     ? "at every angle"
                                     : "at every angle compared (" + std::to_string(v.compared) + " of " +
                                           std::to_string(s.thetas.size()) + ")";
    std::ostringstream md;
    md << "\nThe kernel ran "
       << (s.kernel_law == kernel::silo::SiloContactLaw::yade ? "YADE's Hertz-Mindlin (--kernel-law yade)"
                                                              : "its own contact law (--kernel-law edem)")
       << (s.kernel_rotation == kernel::ClumpRotation::yade_leapfrog
               ? ", its grains turning by YADE's clump rotation in the discharge (--kernel-rotation yade)"
               : "")
       << (s.start_as_yade_import ? ", starting the discharge as YADE's import of the bed (--kernel-start-as-yade-import)"
                                  : "")
       << (s.wall_facets > 0 ? ", between YADE's facet walls in the discharge (--wall-facets " +
                                   std::to_string(s.wall_facets) + ")"
                             : std::string())
       << ".\n\nRates agree when YADE / kernel lies within 1 +/- " << g(s.tolerance)
       << (v.all_agree ? ": they do " + at_every + "." : ": **they do not " + at_every + "**.");
    if (!s.yade_material.is_null())
        md << " YADE ran a different material on purpose (--yade-material " << s.yade_material_file << ").";
    md << " Flow patterns: YADE's frames (at the kernel's frame interval) classified by the kernel's own "
          "classifier with the kernel's settings; "
       << (!v.all_patterns_agree        ? "**not the same " + at_every + "** (marked)."
           : v.all_patterns_determined  ? "the same " + at_every + "."
                                        : "the same wherever both were determined (see each report's message for "
                                          "the others).")
       << "\n\nDifferences YADE cannot remove (yade_scripts/README.md):\n";
    for (const std::string& d : known_differences(s)) md << "- " << d << "\n";
    return md.str();
}

}  // namespace

Report write_report(const fs::path& root, const ReportSettings& s) {
    json report = {{"thetas", s.thetas},
                   {"particles", s.particles},
                   {"stiffness_scale", s.stiffness_scale},
                   {"seed", s.seed},
                   {"angles", json::array()},
                   {"kernel_contact_law", kernel::silo::silo_contact_law_text(s.kernel_law)},
                   {"kernel_discharge_rotation", kernel::silo::silo_clump_rotation_text(s.kernel_rotation)},
                   {"wall_facets", s.wall_facets},
                   {"kernel_start_as_yade_import", s.start_as_yade_import},
                   {"known_differences", known_differences(s)}};
    report["tolerance"] = s.tolerance;
    if (!s.yade_material.is_null()) report["yade_material"] = s.yade_material;
    const YadeRunKind& primary = s.yade_runs.front();
    const bool own_fill_too = s.yade_runs.size() > 1;
    Report out;
    std::ostringstream md, own_fill_md;
    md << kComparisonHeader;
    Verdict verdict;
    for (double theta : s.thetas) {
        const fs::path d = root / angle_folder(theta, s.kernel_law), kd = d / kernel_folder(s.kernel_rotation, s.wall_facets, s.start_as_yade_import);
        if (!fs::exists(kd / "summary.json") || !fs::exists(d / primary.folder / "result.json")) {
            md << "| " << theta << " | (a run failed: see " << d.string() << ") ||||||||||\n";
            out.complete = false;
            continue;
        }
        const KernelSide k = read_kernel_side(kd);
        const YadeSide y = read_yade_side(d, primary);
        const Comparison c = compare(theta, k, y, s.tolerance);
        verdict.add(c);
        md << comparison_row(c, k, y);
        report["angles"].push_back(comparison_json(c, k, y, primary));
        Curve own_curve;
        if (own_fill_too) {
            const YadeRunKind& own_kind = s.yade_runs[1];
            if (!fs::exists(d / own_kind.folder / "result.json")) {
                own_fill_md << "| " << theta << " | (YADE's own filling failed: see " << (d / own_kind.folder).string()
                            << ") ||||||||\n";
                out.complete = false;
            } else {
                const YadeSide own = read_yade_side(d, own_kind);
                own_fill_md << own_fill_row(c, k, own);
                report["angles"].back()["yade_own_fill"] = own_fill_json(c, k, own);
                own_curve = own.curve;
            }
        }
        try {
            write_curve_plot(kd, theta, k.curve, y.curve, own_curve, s.plot_format);  // beside the kernel run it compares
        } catch (const std::exception& e) {
            std::cerr << "demcal: warning: plot not written: " << e.what() << "\n";
        }
    }
    md << closing_text(s, verdict);
    if (own_fill_too) md << kOwnFillSection << own_fill_md.str();
    report["fill_mode"] = s.fill_text;
    // over the angles compared; null where none was (a failed run is no agreement)
    const auto over_compared = [&](bool value) { return verdict.compared > 0 ? json(value) : json(nullptr); };
    report["angles_compared"] = verdict.compared;
    report["complete"] = out.complete;
    report["rates_agree"] = over_compared(verdict.all_agree);
    report["patterns_agree"] = over_compared(verdict.all_patterns_agree);  // where both codes determined one
    report["patterns_determined"] = over_compared(verdict.all_patterns_determined);
    write_result_file(root / "crosscheck_silo.json", report.dump(2) + "\n");
    write_result_file(root / "crosscheck_silo.md", md.str());
    out.markdown = md.str();
    return out;
}

}  // namespace demcal::crosscheck_silo
