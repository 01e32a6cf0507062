#include "app/campaign_cli.hpp"

#include "analytics/failure_line.hpp"
#include "analytics/number_text.hpp"  // trimmed
#include "app/cli_support.hpp"
#include "app/commands.hpp"
#include "orchestrator/shear_params.hpp"

#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace demcal {

void add_campaign_options(CLI::App* cmd, CampaignCli& c) {
    cmd->add_option("--normal-stress,-s", c.normal_stresses, "normal stresses of every failure line [Pa]")
        ->delimiter(',')
        ->check(positive_number())
        ->capture_default_str();
    cmd->add_option("--replicates,-r", c.replicates, "packings per normal stress")
        ->check(integer_in(1, orchestrator::kMaxReplicates))
        ->capture_default_str();
    cmd->add_option("--seed", c.seed, "first packing seed, the same for every material (common random numbers)")
        ->check(integer_in(0, static_cast<long long>(orchestrator::find_shear_param("seed")->max)))
        ->capture_default_str();
    cmd->add_option("--engine", c.engine, "yade or kernel (the same shear box on demcal's kernel with YADE's laws)")
        ->check(CLI::IsMember({"yade", "kernel"}))
        ->capture_default_str();
    cmd->add_option("--campaign,--dir,-c", c.campaign_dir, "campaign directory (store, runs, results)")
        ->capture_default_str();
    cmd->add_option("--template", c.template_path, "YADE template (default: yade_scripts/shear_box.py)");
    cmd->add_option("--line", c.line, "failure line to work on")->check(CLI::IsMember({"peak", "residual"}));
    cmd->add_option("--plot", c.plot_format, "plot format")->check(CLI::IsMember({"png", "svg"}))->capture_default_str();
    add_execution_options(cmd, c.exec);
}

std::map<std::string, std::pair<double, double>> parse_ranges(const std::vector<std::string>& items,
                                                              const std::string& option) {
    std::map<std::string, std::pair<double, double>> out;
    for (const auto& typed : items) {
        // blanks around the parts are no part of them ("young_modulus = 1e7 : 2e7")
        const std::string item = [&typed] {
            std::string t = analytics::trimmed(typed);
            for (const char sep : {'=', ':'})
                if (const auto at = t.find(sep); at != std::string::npos)
                    t = analytics::trimmed(t.substr(0, at)) + sep + analytics::trimmed(t.substr(at + 1));
            return t;
        }();
        const auto eq = item.find('='), colon = item.find(':');
        double lo = NAN, hi = NAN;
        bool ok = eq != std::string::npos && colon != std::string::npos && colon > eq;
        if (ok) {
            try {
                std::size_t a = 0, b = 0;
                const std::string l = item.substr(eq + 1, colon - eq - 1), h = item.substr(colon + 1);
                lo = std::stod(l, &a);
                hi = std::stod(h, &b);
                ok = a == l.size() && b == h.size();
            } catch (const std::exception&) {
                ok = false;
            }
        }
        if (!ok)  // shown as typed (the trimmed item showed " " as '')
            throw UserError(option + " '" + analytics::shortened_text(typed) + "' is not of the form NAME=LOW:HIGH");
        const std::string name = item.substr(0, eq);
        if (!orchestrator::find_shear_param(name)) throw UserError(option + " '" + item + "': unknown parameter '" + name + "'");
        if (out.count(name))  // the last one silently won
            throw UserError(option + " '" + item + "': a range for " + name + " is given twice");
        // the number rule of every number typed (nan:0.9 was refused as "must have low < high"), and the order
        for (const auto& [which, value] : {std::pair<const char*, double>{"low", lo}, {"high", hi}})
            if (const auto defect = analytics::number_defect(value))
                throw UserError(option + " '" + analytics::shortened_text(item) + "': its " + which + " end " + *defect);
        if (!(lo < hi))
            throw UserError(option + " '" + analytics::shortened_text(item) + "': its low end must be below its high end");
        out[name] = {lo, hi};
    }
    return out;
}

calibration::CampaignSettings settings_of(const CampaignCli& c, const std::string& label) {
    return {c.normal_stresses, c.replicates, c.seed, c.template_path, label, orchestrator::parse_shear_engine(c.engine)};
}

void check_campaign(const CampaignCli& c, const nlohmann::json& material) {
    try {
        analytics::check_failure_line_design(c.normal_stresses, c.replicates);
    } catch (const std::invalid_argument& e) {
        throw UserError(e.what());
    }
    if (c.engine == "kernel" && !c.template_path.empty())
        throw UserError("--template = '" + c.template_path + "' is a YADE script: it applies to --engine yade only");
    orchestrator::validate_shear_spec(settings_of(c, "check").spec_for(material));
}

std::string runs_cpu_text(double cpu_seconds, int reused_runs) {
    return "CPU " + cpu_duration(cpu_seconds) +
           (reused_runs > 0 ? " (the " + std::to_string(reused_runs) + " reused run" + (reused_runs > 1 ? "s'" : "'s") +
                                  " own included)"
                            : "");
}

std::string cpu_duration(double s) {
    std::ostringstream o;
    if (s >= 3600)
        o << std::fixed << std::setprecision(1) << s / 3600 << " h";
    else if (s >= 60)
        o << std::fixed << std::setprecision(1) << s / 60 << " min";
    else
        o << std::fixed << std::setprecision(0) << s << " s";
    return o.str();
}

CampaignSession::CampaignSession(const CampaignCli& c, const std::string& label) {
    if (c.engine == "yade") orchestrator::find_yade(c.exec.yade);
    runner = std::make_unique<orchestrator::ShearCampaignRunner>(c.campaign_dir, c.exec);
    const calibration::CampaignSettings settings = settings_of(c, label);
    auto progress = [](const orchestrator::CampaignProgress& p) {
        if (p.event != "failed" && p.event != "retry") return;  // the commands print one line per failure line
        std::cout << "    run " << p.event << " (sigma = " << (p.run ? p.run->label.value("normal_stress", 0.0) : 0)
                  << " Pa): " << (p.run ? p.run->cause + ": " + p.run->message : "") << std::endl;
    };
    evaluate = calibration::campaign_evaluator(*runner, settings, progress);
}

}  // namespace demcal
