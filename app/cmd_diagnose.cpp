// demcal predict GEOMETRY.json: every discharge model's rate with its validity.
#include "analytics/discharge_models.hpp"
#include "app/commands.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

namespace demcal {

namespace {

constexpr const char* geometry_keys_help = R"(GEOMETRY.json keys (SI units, angles in degrees):
  geometry      "conical" (cylindrical silo with a conical hopper) or "rectangular"
  D_m           silo diameter (conical)
  b_m, c_m      silo depth and width (rectangular; the slot outlet spans the depth b)
  outlet_m      outlet diameter d (conical) or slot width a (rectangular)
  theta_deg     hopper half angle from the vertical, 90 = flat bottom
  d_p_m         particle size
  rho_b_kg_m3   bulk density
optional model constants (defaults in brackets):
  beverloo_C [0.58], beverloo_k [1.5], slot_C [1.03] (Myers-Sellers slot), delta [0.5] (Oldal's arch),
  phi_d_deg [45] (Rose-Tanaka stagnant-zone angle to the horizontal),
  delta_e_deg, phi_w_deg (effective internal and wall friction angles: with both, Jenike's mass-flow limit decides
  the flow pattern and each model says whether it applies))";

nlohmann::json read_json_file(const std::string& path, const char* what) {
    std::ifstream in(path);
    if (!in) throw UserError(std::string(what) + ": cannot open " + path);
    try {
        return nlohmann::json::parse(in);
    } catch (const nlohmann::json::parse_error& e) {
        throw UserError(std::string(what) + ": " + path + " is not valid JSON: " + e.what());
    }
}

void write_text(const std::string& path, const std::string& text) {
    std::ofstream out(path);
    if (!out) throw UserError("cannot write " + path);
    out << text;
    if (!out) throw UserError("failed writing " + path);
}

std::string fixed(double v, int digits) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", digits, v);
    return buf;
}

void run_predict(const std::string& geometry_path, const std::string& json_out) {
    analytics::SiloGeometry geometry;
    try {
        geometry = analytics::geometry_from_json(read_json_file(geometry_path, "predict"));
    } catch (const std::invalid_argument& e) {
        throw UserError(geometry_path + ": " + e.what());
    }
    const auto predictions = analytics::predict_discharge(geometry);
    std::cout << "model                  W [kg/s]   valid  notes\n";
    for (const auto& p : predictions) {
        std::string line = p.model;
        line.resize(22, ' ');
        std::string rate = p.rate ? fixed(*p.rate, 4) : "-";
        rate.resize(10, ' ');
        std::cout << line << " " << rate << " " << (p.valid ? "yes  " : "NO   ") << "  ";
        for (size_t i = 0; i < p.warnings.size(); ++i) std::cout << (i ? "; " : "") << p.warnings[i];
        std::cout << "\n";
    }
    if (!json_out.empty()) {
        nlohmann::json j{{"geometry", geometry_path}, {"predictions", nlohmann::json::array()}};
        for (const auto& p : predictions) j["predictions"].push_back(p.to_json());
        if (geometry.effective_friction_deg)
            j["jenike_mass_flow_limit_deg"] =
                analytics::jenike_mass_flow_limit_deg(*geometry.effective_friction_deg, *geometry.wall_friction_deg);
        write_text(json_out, j.dump(2) + "\n");
    }
}

}  // namespace

void add_discharge_commands(CLI::App& app) {
    auto predict = app.add_subcommand("predict", "Discharge rate of a silo by every analytical model, with validity");
    auto geometry = std::make_shared<std::string>();
    auto predict_json = std::make_shared<std::string>();
    predict->add_option("GEOMETRY", *geometry, "silo geometry JSON (keys below)")->required();
    predict->add_option("--json", *predict_json, "also write the predictions as JSON to this file");
    predict->footer(geometry_keys_help);
    predict->callback([geometry, predict_json] { run_predict(*geometry, *predict_json); });
}

}  // namespace demcal
