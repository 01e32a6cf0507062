// demcal shear-run PARAMS RESULT: one shear box on the kernel engine, as a campaign runs it (the orchestrator starts it
// as a subprocess, so timeouts, kill -9, retries and SLURM hold exactly as for YADE). It speaks the YADE script's
// protocol: params.json in, result.json (schema demcal.shear_result/3, sealed with its SHA-256 as
// orchestrator/run_identity.hpp says) written atomically, exit 2 with
// `DEMCAL_FAILURE params: ...` for bad parameters, exit 3 with `DEMCAL_FAILURE <cause>: ...` for a run that failed.
#include "app/cli_support.hpp"
#include "app/commands.hpp"
#include "analytics/user_input.hpp"
#include "kernel/cases/shear_box.hpp"
#include "orchestrator/run_identity.hpp"
#include "orchestrator/shear_params.hpp"

#include <nlohmann/json.hpp>

#include <iostream>

namespace demcal {

namespace {

using kernel::cases::ShearBoxParams;
using kernel::cases::ShearBoxResult;

[[noreturn]] void fail(int code, const std::string& cause, std::string details) {
    for (char& c : details)
        if (c == '\n') c = ' ';
    std::cout.flush();
    std::cerr << "DEMCAL_FAILURE " << cause << ": " << details << std::endl;
    throw CLI::RuntimeError(code);
}

// The run's parameters through the same table and checks as every campaign's (orchestrator/shear_params.cpp).
nlohmann::json checked_run_params(const nlohmann::json& raw, const std::string& where) {
    if (!raw.is_object()) throw std::invalid_argument(where + ": must hold a JSON object");
    nlohmann::json material = raw;
    for (const char* per_run : {"normal_stress", "seed"}) {
        if (!raw.contains(per_run))
            throw std::invalid_argument(where + ": missing field '" + per_run + "'");
        material.erase(per_run);
    }
    if (!raw["seed"].is_number_integer()) throw std::invalid_argument(where + ": field 'seed' must be an integer");
    // checked as read: get<long> wrapped 18446744073709551615 to -1, which the message then showed
    orchestrator::check_shear_param_value("seed", raw["seed"], where);
    if (!raw["normal_stress"].is_number()) throw std::invalid_argument(where + ": field 'normal_stress' must be a number");
    return orchestrator::make_run_params(orchestrator::validate_material(material, where),
                                         raw["normal_stress"].get<double>(), raw["seed"].get<long>(), where);
}

ShearBoxParams to_kernel_params(const nlohmann::json& j) {
    ShearBoxParams p;
    auto d = [&](const char* k) { return j.at(k).get<double>(); };
    p.density = d("density");
    p.young_modulus = d("young_modulus");
    p.poisson_ratio = d("poisson_ratio");
    p.friction_coefficient = d("friction_coefficient");
    p.bond_normal_strength = d("bond_normal_strength");
    p.bond_shear_strength = d("bond_shear_strength");
    p.particle_form = d("particle_form");
    p.timestep_fraction = d("timestep_fraction");
    p.particle_radius = d("particle_radius");
    p.radius_spread = d("radius_spread");
    p.box_length = d("box_length");
    p.box_width = d("box_width");
    p.box_height = d("box_height");
    p.normal_stress = d("normal_stress");
    p.shear_velocity = d("shear_velocity");
    p.shear_displacement = d("shear_displacement");
    p.damping = d("damping");
    p.seed = j.at("seed").get<long>();
    p.samples = j.at("samples").get<int>();
    return p;
}

nlohmann::json to_json(const ShearBoxResult& r, const nlohmann::json& params_as_read) {
    return {{"schema", orchestrator::kShearResultSchema},
            {"params", params_as_read},
            {"curve",
             {{"displacement", r.displacement},
              {"shear_stress", r.shear_stress},
              {"normal_stress", r.normal_stress},
              {"lid_height", r.lid_height}}},
            {"peak_shear_stress", r.peak_shear_stress},
            {"peak_displacement", r.peak_displacement},
            {"residual_shear_stress", r.residual_shear_stress},
            {"residual_shear_stress_std", r.residual_shear_stress_std},
            {"normal_stress_target", r.normal_stress_target},
            {"normal_stress_held", r.normal_stress_held},
            {"normal_stress_rel_dev", r.normal_stress_rel_dev},
            {"porosity", r.porosity},
            {"particle_count", r.particle_count},
            {"growth_steps", r.growth_steps},
            {"sphere_count", r.sphere_count},
            {"spheres_per_particle", r.spheres_per_particle},
            {"sphere_spacing_over_radius", r.sphere_spacing_over_radius},
            {"bond_count", r.bond_count},
            {"sheared_area", r.sheared_area},
            {"consolidated_height", r.consolidated_height},
            {"consolidation_steps", r.consolidation_steps},
            {"consolidation_unbalanced_force", r.consolidation_unbalanced_force},
            {"consolidation_overshoot", r.consolidation_overshoot},
            {"growth_lid_force_peak_ratio", r.growth_lid_force_peak_ratio},
            {"inertial_number", r.inertial_number},
            {"steps", r.steps},
            {"timestep", r.timestep},
            {"wall_time_s", r.wall_time_s},
            {"engine", kernel::cases::kShearBoxEngine}};
}

void run(const std::string& params_path, const std::string& result_path, int threads) {
    ShearBoxParams params;
    nlohmann::json params_as_read;  // recorded in the result: whose result it is (orchestrator::params_digest)
    try {
        const nlohmann::json raw = analytics::read_json_input(params_path, "params");
        params_as_read = raw;
        params = to_kernel_params(checked_run_params(raw, params_path));
        kernel::cases::validate(params);
    } catch (const kernel::cases::ShearBoxFailure& e) {
        fail(2, "params", e.what());
    } catch (const std::exception& e) {
        fail(2, "params", e.what());
    }
    try {  // before the run, not after it: a result that cannot be written is a run wasted
        check_output_file(result_path, "result");
        check_paths_apart({{params_path, "params (the input file)"}}, {{result_path, "result"}});
    } catch (const UserError& e) {
        fail(2, "output", e.what());
    }
    ShearBoxResult result;
    try {
        result = kernel::cases::run_shear_box(params, [](const std::string& line) { std::cout << line << std::endl; },
                                              threads);
    } catch (const kernel::cases::ShearBoxFailure& e) {
        fail(e.cause == "params" ? 2 : 3, e.cause, e.what());
    }
    try {
        orchestrator::write_text_file_atomically(result_path,
                                                 orchestrator::sealed_result_text(to_json(result, params_as_read).dump(1) + "\n"));
    } catch (const std::exception& e) {
        fail(3, "output", e.what());
    }
}

}  // namespace

void add_shear_run_command(CLI::App& app) {
    struct Options {
        std::string params = "params.json", result = "result.json";
        int threads = 1;
    };
    auto opt = std::make_shared<Options>();
    auto* cmd = app.add_subcommand("shear-run",
                                   "one shear box on the kernel engine (what a campaign with --engine kernel runs)");
    cmd->add_option("params", opt->params, "params.json of the run (the YADE script's fields)");
    cmd->add_option("result", opt->result, "result.json to write");
    cmd->add_option("--threads", opt->threads, "OpenMP threads (the result does not depend on them)")
        ->check(integer_in(1, 256));
    cmd->callback([opt] { run(opt->params, opt->result, opt->threads); });
}

}  // namespace demcal
