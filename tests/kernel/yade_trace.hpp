// Reading YADE's single-contact reference traces (tests/data/yade_contact/, made by yade_scripts/single_contact.py with
// real YADE) and replaying a trace's prescribed path through one of the kernel's contact laws: shared by the tests of
// each YADE law the kernel reproduces (test_yade_laws.cpp: the shear box's linear law; test_yade_mindlin.cpp: the
// silo's Hertz-Mindlin).
#pragma once
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "kernel/simulation.hpp"

namespace demcal::test::yade_trace {

using namespace demcal::kernel;
using json = nlohmann::json;

inline const std::string kData = std::string(DEMCAL_SOURCE_DIR) + "/tests/data/yade_contact/";

struct Trace {
  std::vector<std::map<std::string, double>> rows;
  double peak(const std::string& prefix) const {
    double p = 0;
    for (const auto& r : rows) p = std::max(p, Vec3(r.at(prefix + "x"), r.at(prefix + "y"), r.at(prefix + "z")).norm());
    return p;
  }
};

inline Trace read_trace(const std::string& file) {
  std::ifstream is(file);
  REQUIRE(is);
  std::string line;
  std::getline(is, line);
  std::vector<std::string> cols;
  {
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cols.push_back(c);
  }
  Trace t;
  while (std::getline(is, line)) {
    std::stringstream ss(line);
    std::map<std::string, double> row;
    std::size_t k = 0;
    for (std::string c; std::getline(ss, c, ',') && k < cols.size(); ++k) row[cols[k]] = std::stod(c);
    t.rows.push_back(row);
  }
  return t;
}

inline json read_params(const std::string& c) {
  std::ifstream is(kData + c + ".json");
  REQUIRE(is);
  return json::parse(is);
}

inline Vec3 vec(const json& a) { return Vec3(a[0].get<double>(), a[1].get<double>(), a[2].get<double>()); }
inline Vec3 vec(const std::map<std::string, double>& r, const std::string& p) { return Vec3(r.at(p + "x"), r.at(p + "y"), r.at(p + "z")); }

inline Material material(const json& m) { return {m["young"].get<double>(), m["poisson"].get<double>(), m["density"].get<double>(), ""}; }

inline double rel_error(const Vec3& kernel, const Vec3& yade, double peak) {
  return (kernel - yade).norm() / std::max({yade.norm(), 1e-9 * peak, 1e-300});
}


// Replays a prescribed path (the moving sphere = i, the fixed sphere or box = j) through Law, step by step, with the
// geometry and kinematics the kernel's loops build (m*: the two spheres' masses, as YADE's two non-dynamic bodies;
// the wall: the sphere's), and returns the largest relative error of the force and
// torque on the moving sphere and of the torque on the fixed sphere over the sampled steps.
/// The mass YADE's utils.sphere gives a body of the trace ("moving" or "fixed"): density x 4/3 pi r^3.
inline double sphere_mass(const json& p, const std::string& body, double r) {
  return p["materials"][p[body]["material"].get<std::string>()]["density"].get<double>() * 4.0 / 3.0 * M_PI * r * r * r;
}

/// The trace's fixed facet (fixed.vertices) as the kernel's triangular wall: YADE's facet contact, edges and vertices
/// included (kernel/walls/triangle_wall.hpp).
inline Wall facet_wall(const json& fixed) {
  const json& v = fixed["vertices"];
  REQUIRE(v.size() == 3);
  return Wall::triangle(vec(v[0]), vec(v[1]), vec(v[2]), 0);
}

template <class Law>
double replay(const std::string& name, const std::function<typename Law::Params(const json&, const json&)>& pair_params) {
  const json p = read_params(name);
  const Trace t = read_trace(kData + name + ".csv");
  const double dt = p["dt"];
  // a wall: a box or a facet
  const bool box = p["case"] == "sphere_box" || p["case"] == "sphere_facet";
  const json& mat_i = p["materials"][p["moving"]["material"].get<std::string>()];
  const json& mat_j = p["materials"][p["fixed"]["material"].get<std::string>()];
  const typename Law::Coeffs coeffs = Law::mix(material(mat_i), material(mat_j), pair_params(mat_i, mat_j));
  const double ri = p["moving"]["radius"];
  const double rj = box ? 0.0 : p["fixed"]["radius"].get<double>();
  const Vec3 xj = p["case"] == "sphere_facet" ? Vec3::Zero() : vec(box ? p["fixed"]["center"] : p["fixed"]["pos"]);
  const double mi = sphere_mass(p, "moving", ri), mj = box ? 0.0 : sphere_mass(p, "fixed", rj);
  Wall wall;
  if (p["case"] == "sphere_facet") wall = facet_wall(p["fixed"]);
  else if (box) wall = Wall::box(xj - vec(p["fixed"]["extents"]), xj + vec(p["fixed"]["extents"]), 0);
  std::vector<std::pair<Vec3, Vec3>> path;  // velocity, angular velocity per step
  for (const json& seg : p["path"])
    for (int k = 0; k < seg["steps"].get<int>(); ++k) path.emplace_back(vec(seg["vel"]), vec(seg.value("angvel", json::array({0, 0, 0}))));
  const int bond_at = p.value("bond_at_step", -1);
  std::map<int, const std::map<std::string, double>*> sampled;
  for (const auto& r : t.rows) sampled[int(r.at("step"))] = &r;
  const double peak_f = t.peak("b1_f_"), peak_ti = t.peak("b1_t_"), peak_tj = box ? 1.0 : t.peak("b0_t_");
  double hist[Law::history_size] = {};
  Vec3 xi = vec(p["moving"]["pos"]);
  double worst = 0;
  int compared = 0;
  for (std::size_t k = 0; k < path.size(); ++k) {
    const auto [vi, wi] = path[k];
    ContactGeometry g{};
    bool touching;
    if (box) {
      Vec3 n = Vec3::Zero();
      double dn = 0, dist = 0;
      touching = wall.contact(xi, ri, n, dn, dist);
      g = {n, dn, ri, mi, ri, 0.0, ri - 0.5 * dn, 0.0};
    } else {
      const Vec3 d = xi - xj;
      const double dist = d.norm();
      g = {d / dist, ri + rj - dist, ri * rj / (ri + rj), mi * mj / (mi + mj), ri, rj, 0, 0};
      g.lever_i = ri - 0.5 * g.dn;
      g.lever_j = rj - 0.5 * g.dn;
      touching = g.dn > -Law::reach(coeffs, std::max(ri, rj)) - 1e-12;
    }
    ContactResult res;
    bool acting = touching && Law::acts(coeffs, g, hist);
    if (acting) {
      ContactKinematics kin;
      kin.v_i = vi;
      kin.v_j = Vec3::Zero();
      kin.omega_i = wi;
      kin.omega_j = Vec3::Zero();
      kin.v_rel = vi - g.lever_i * wi.cross(g.n);
      res = Law::compute(coeffs, g, kin, hist, dt, box, int(k) == bond_at);
    } else {
      std::fill(std::begin(hist), std::end(hist), 0.0);
    }
    if (auto it = sampled.find(int(k)); it != sampled.end()) {
      const auto& r = *it->second;
      INFO(name << " step " << k);
      CHECK((vec(r, "b1_pos_") - xi).norm() <= 1e-12 * xi.norm());
      CHECK(acting == (r.at("real") == 1.0));
      if (acting && r.at("cohesion_broken") >= 0) CHECK((hist[0] == 0.0) == (r.at("cohesion_broken") == 1.0));
      worst = std::max(worst, rel_error(res.force_i, vec(r, "b1_f_"), peak_f));
      worst = std::max(worst, rel_error(res.torque_i, vec(r, "b1_t_"), peak_ti));
      if (!box) worst = std::max(worst, rel_error(res.torque_j, vec(r, "b0_t_"), peak_tj));
      ++compared;
    }
    xi += dt * vi;
  }
  CHECK(compared > 50);
  return worst;
}

}  // namespace demcal::test::yade_trace
