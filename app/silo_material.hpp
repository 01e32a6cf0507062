// The silo's material file (demcal silo --material FILE.json): the grain, the wall and the two pair sets of the seed's
// Table 2.1, every physical field required (grain.shape, the one "wheat-clump", may be left out), E or G for each
// solid, unknown keys refused. The seed's wheat is
// examples/materials/silo_wheat_table21.json (equal to the built-in default).
#pragma once
#include <nlohmann/json.hpp>

#include <string>

#include "kernel/silo/wheat.hpp"

namespace demcal {

/// Reads FILE into the silo's materials (the stiffness scale is left as it is). Throws UserError naming the file, the
/// field and the value; `what` names the input (the option without its dashes) where the file is unreadable.
kernel::silo::WheatMaterials read_silo_material(const std::string& file, const std::string& what = "material");

/// The materials as a material file spells them (G for each solid, unscaled; the stiffness scale is not part of it):
/// read_silo_material reads it back to the same values.
nlohmann::json silo_material_json(const kernel::silo::WheatMaterials& m);

}  // namespace demcal
