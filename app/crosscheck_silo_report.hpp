// The report of `demcal crosscheck silo`: the kernel's and YADE's runs of each angle, read from the campaign folder,
// side by side (rates with their uncertainty, time to empty, flow patterns by the kernel's classifier, the largest gap
// between the mass-time curves, CPU times), the filling's share with --fill both, and the differences YADE cannot
// remove. Written as JSON, a Markdown table and one mass-time plot per angle.
#pragma once

#include "kernel/silo/silo_case.hpp"
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace demcal::crosscheck_silo {

// A YADE run of one angle: its folder, the bed file it starts from, and whether it fills first.
struct YadeRunKind {
    const char* folder;
    const char* bed_file;
    bool fills;
    const char* label;
};
inline constexpr YadeRunKind kYadeSameBed{"yade", "bed.json", false, "YADE from the kernel's filled bed"};
inline constexpr YadeRunKind kYadeOwnFill{"yade-own-fill", "cloud.json", true,
                                          "YADE filling on its own from the kernel's generated cloud"};

// yade_scripts/silo.py writes its flow-pattern frames here, in its run folder.
inline constexpr const char* kYadeFramesFile = "frames.bin";

// The folder of one angle's runs in the campaign: theta_<deg>.
std::string theta_name(double theta);
// The folder of one angle's runs on a kernel contact law: theta_<deg> on the kernel's own (the layout of campaigns
// made before the choice), theta_<deg>_law-<name> otherwise: the kernel fills with its law, so the bed, YADE's runs of
// it and the kernel's run all belong to the law, and a campaign switching laws must not mix them.
std::string angle_folder(double theta, kernel::silo::SiloContactLaw law);
// The kernel run's folder within an angle's, per discharge rotation: "kernel" for the kernel's own, kernel-rotation-
// <name> otherwise. The filling is the same whichever scheme discharges, so the bed and YADE's runs of it are shared.
std::string kernel_folder(kernel::ClumpRotation rotation, int wall_facets = 0, bool start_as_yade_import = false);

struct ReportSettings {
    std::vector<double> thetas;
    int particles = 0;
    double stiffness_scale = 0;
    long seed = 0;
    double tolerance = 0;                // rates agree when YADE / kernel lies within 1 +/- this
    nlohmann::json yade_material;        // null: YADE ran the bed's material
    std::string yade_material_file;      // its file, for the report's note
    std::string fill_text;               // same-bed | own | both
    kernel::silo::SiloContactLaw kernel_law = kernel::silo::SiloContactLaw::edem;  // demcal silo --contact-law
    kernel::ClumpRotation kernel_rotation = kernel::ClumpRotation::richardson;     // demcal silo --discharge-rotation
    int wall_facets = 0;  // 0: the kernel's exact walls beside YADE's 72 facets; N: both codes on N facets around
    bool start_as_yade_import = false;  // demcal silo --start-as-yade-import
    std::vector<YadeRunKind> yade_runs;  // the first is compared with the kernel; a second is YADE's own filling
    std::string plot_format = "png";
};

struct Report {
    std::string markdown;
    bool complete = true;  // every angle's runs gave results
};

// Reads the runs of every angle under `root`, writes root/crosscheck_silo.{json,md} and, beside each kernel run,
// root/<angle_folder>/<kernel_folder>/mass_time.<fmt>.
Report write_report(const std::filesystem::path& root, const ReportSettings& settings);

}  // namespace demcal::crosscheck_silo
