// demcal silo --export-bed FILE: the kernel's filled bed at the moment the outlet opens, written as JSON for another
// code (yade_scripts/silo.py) to start the same discharge from it. Format: schema "demcal.silo_bed/1", described in
// yade_scripts/README.md (silo section).
#pragma once
#include <nlohmann/json.hpp>

#include <filesystem>

#include "kernel/silo/silo_case.hpp"

namespace demcal {

inline constexpr const char* kSiloBedSchema = "demcal.silo_bed/1";

/// The geometry as the --geometry file spells it (shape, theta_deg, outlet_m, D_m or a_m/b_m/c_m, body_height_m) and
/// the derived hopper height: one spelling for summary.json and the bed file.
nlohmann::json silo_geometry_json(const kernel::silo::SiloGeometry& g);

/// When a bed was taken: at the opening (the bed to discharge), at the generation (the cloud to fill), or when the
/// discharge ended (the grains left, to compare with another code's run of the same bed).
enum class BedMoment { opening, generation, end };

/// The bed with everything needed to rebuild the run elsewhere: the moment, geometry, materials as a --material file
/// spells them (unscaled) and the stiffness scale, gravity, removal depth, time step, the filling's rest criterion,
/// the flow-pattern sampling, the clump template and every grain.
nlohmann::json silo_bed_json(const kernel::silo::BedSnapshot& bed, const kernel::silo::SiloCaseSettings& s,
                             BedMoment moment);

/// silo_bed_json written to `file` atomically (a temporary file renamed over it). Throws std::runtime_error naming
/// `option` and the file when it cannot be written.
void write_silo_bed(const std::filesystem::path& file, const kernel::silo::BedSnapshot& bed,
                    const kernel::silo::SiloCaseSettings& s, BedMoment moment, const std::string& option);

}  // namespace demcal
