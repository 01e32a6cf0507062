#include "app/silo_bed_export.hpp"

#include "app/silo_flow_pattern.hpp"
#include "app/silo_material.hpp"
#include "orchestrator/run_identity.hpp"  // write_text_file_atomically

#include <stdexcept>
#include <string>

namespace demcal {

namespace ks = kernel::silo;
using json = nlohmann::json;

namespace {

json xyz(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

json wxyz(const Eigen::Quaterniond& q) { return json::array({q.w(), q.x(), q.y(), q.z()}); }

// The template in its principal frame: what a rigid-body code needs (mass, principal moments, members).
json clump_json(const kernel::ClumpTemplate& t) {
    json members = json::array();
    for (size_t k = 0; k < t.offsets.size(); ++k)
        members.push_back({{"offset_m", xyz(t.offsets[k])}, {"radius_m", t.radii[k]}});
    return {{"frame", "principal: the centre of mass at the origin, axes along the principal axes of inertia"},
            {"members", members},
            {"density_kg_m3", t.density},
            {"volume_m3", t.volume},
            {"mass_kg", t.mass},
            {"principal_inertia_kg_m2", xyz(t.inertia)}};
}

// Column arrays (one entry per grain): compact, and a reader takes one quantity at a time.
json grains_json(const std::vector<ks::BedGrain>& grains) {
    json position = json::array(), orientation = json::array(), velocity = json::array(), spin = json::array(),
         spheres = json::array();
    for (const ks::BedGrain& g : grains) {
        position.push_back(xyz(g.position));
        orientation.push_back(wxyz(g.orientation));
        velocity.push_back(xyz(g.velocity));
        spin.push_back(xyz(g.angular_velocity));
        json centres = json::array();
        for (const auto& c : g.spheres) centres.push_back(xyz(c));
        spheres.push_back(centres);
    }
    return {{"count", grains.size()},
            {"position_m", position},
            {"orientation_wxyz", orientation},
            {"velocity_m_s", velocity},
            {"angular_velocity_rad_s", spin},
            {"sphere_centres_m", spheres}};
}

}  // namespace

json silo_geometry_json(const ks::SiloGeometry& g) {
    json j;
    if (g.shape == ks::SiloShape::conical)
        j = {{"shape", "conical"}, {"D_m", g.diameter}, {"outlet_m", g.outlet}};
    else
        j = {{"shape", "rectangular"}, {"a_m", g.outlet}, {"b_m", g.depth}, {"c_m", g.width}};
    j["theta_deg"] = g.half_angle_deg;
    j["body_height_m"] = g.body_height;
    j["hopper_height_m"] = g.hopper_height();
    return j;
}

json silo_bed_json(const ks::BedSnapshot& bed, const ks::SiloCaseSettings& s, BedMoment moment) {
    json geometry = silo_geometry_json(s.geometry);
    geometry["wall_top_m"] = bed.wall_top;
    const bool opening = moment == BedMoment::opening;
    const char* name = opening ? "opening" : moment == BedMoment::generation ? "generation" : "end";
    const char* what = opening ? "the kernel's bed at the opening of the outlet, before the first discharge step"
                       : moment == BedMoment::generation
                           ? "the kernel's generated cloud of grains, before the first filling step (the outlet closed)"
                           : "the grains left in the kernel's silo when its discharge ended (time_s: since the start)";
    return {{"schema", kSiloBedSchema},
            {"moment", name},
            {"note", std::string(what) +
                         "; SI units; orientation_wxyz: unit quaternion of the clump's principal frame "
                         "(clump_template.frame) to the world; velocities on-step (velocity Verlet); "
                         "sphere_centres_m: the kernel's own member centres, for checking an import"},
            {"fill",
             {{"rest_energy_per_grain_J", bed.rest_energy},
              {"time_min_s", s.fill_time_min},
              {"time_max_s", s.fill_time_max},
              {"rule", "the filling ends at the first record interval after time_min_s where the mean kinetic "
                       "energy per grain (translational and rotational) is below rest_energy_per_grain_J, or at "
                       "time_max_s"}}},
            {moment == BedMoment::end ? "time_s" : "opening_time_s", bed.time},
            {"time_step_s", bed.time_step},
            {"time_step_fraction", s.time_step_fraction},
            {"gravity_m_s2", s.gravity},
            {"removal_depth_m", s.removal_depth},
            {"record_interval_s", s.record_interval},
            {"flow_pattern_sampling", flow_pattern_sampling_json(s)},
            {"geometry", geometry},
            {"material", silo_material_json(s.materials)},
            {"stiffness_scale", s.materials.stiffness_scale},
            {"clump_template", clump_json(bed.grain)},
            {"filled_mass_kg", bed.grain.mass * double(bed.grains.size())},
            {"grains", grains_json(bed.grains)}};
}

void write_silo_bed(const std::filesystem::path& file, const ks::BedSnapshot& bed, const ks::SiloCaseSettings& s,
                    BedMoment moment, const std::string& option) {
    try {
        orchestrator::write_text_file_atomically(file, silo_bed_json(bed, s, moment).dump() + "\n");
    } catch (const std::exception& e) {
        throw std::runtime_error(option + " = '" + file.string() + "': cannot write the bed: " + e.what());
    }
}

}  // namespace demcal
