# -*- coding: utf-8 -*-
"""Silo discharge in YADE 2023.02a from the demcal kernel's filled bed (issue 22: the same discharge in both codes).

Run:  cd RUNDIR && yade -n -j1 -x silo.py [params.json] [result.json]

Sequence:
  1. the silo is built from facets: the cone with the outlet, the cylindrical body above it, and the outlet plate;
  2. every grain of the bed file (`demcal silo --export-bed`) becomes a rigid clump placed exactly at the kernel's
     centre of mass, orientation, velocity and angular velocity, with the kernel's mass and principal inertia;
  3. the outlet plate is removed (t = 0 is the kernel's opening) and the grains discharge under gravity with
     Hertz-Mindlin set up to match the kernel (yade_scripts/README.md, silo section, lists what differs and why);
  4. every sampling interval the clumps whose centre is removal_depth below the outlet are counted as discharged
     and erased, as the kernel does; the discharged mass against time and its steady-part slope go to result.json.

Output: result.json (schema demcal.silo_result/1), written atomically; with run.readback_file also the bed as YADE
holds it at t = 0. Failures: exit 3 and one line `DEMCAL_FAILURE <cause>: <details>` on stderr; bad params or bed
file: exit 2 with `DEMCAL_FAILURE params: <field>=<value> <reason>`. Every parameter is declared in PARAM_SPECS.
"""
import json
import math
import os
import struct
import sys
import time
from array import array

from yade import utils

WALL_CLOCK_START = time.time()
CPU_START = time.process_time()

SCHEMA = "demcal.silo_result/1"
BED_SCHEMA = "demcal.silo_bed/1"
READBACK_SCHEMA = "demcal.silo_readback/1"
FRAMES_SCHEMA = "demcal.silo_frames/1"
REQUIRED = object()


def number(unit, lo, hi, meaning, default=REQUIRED, lo_open=False, hi_open=False, integer=False):
    return {"unit": unit, "lo": lo, "hi": hi, "lo_open": lo_open, "hi_open": hi_open, "integer": integer,
            "default": default, "meaning": meaning}


def text(meaning, choices=None, default=REQUIRED):
    return {"unit": None, "choices": choices, "default": default, "meaning": meaning}


def solid_specs(prefix, what, shape=False):
    specs = {
        prefix + ".shear_modulus_Pa": number("Pa", 1e3, 1e12, what + " shear modulus G (give G or E)", default=None),
        prefix + ".young_Pa": number("Pa", 1e3, 1e13, what + " Young modulus E = 2 G (1 + nu) (give G or E)",
                                     default=None),
        prefix + ".poisson": number("-", -1.0, 0.5, what + " Poisson ratio", lo_open=True, hi_open=True),
        prefix + ".density_kg_m3": number("kg/m^3", 10.0, 1e5, what + " density"),
    }
    if shape:
        specs[prefix + ".shape"] = text("grain shape: the seed's 3-sphere clump (the bed file gives its members)",
                                        choices=("wheat-clump",), default="wheat-clump")
        # the kernel's bounds (kernel/silo/wheat.hpp); the members themselves come from the bed file
        specs[prefix + ".aspect_ratio"] = number("-", 1.0, 2.6, "grain length / width of the 3-sphere clump "
                                                 "(the seed's 11/6; the bed file gives its members)",
                                                 default=11.0 / 6.0)
    return specs


def pair_specs(prefix, what):
    return {
        prefix + ".restitution": number("-", 0.0, 1.0, what + " coefficient of restitution", lo_open=True),
        prefix + ".friction": number("-", 0.0, 10.0, what + " sliding friction coefficient"),
        prefix + ".rolling_friction": number("-", 0.0, 1.0, what + " rolling friction coefficient (kernel: EDEM's "
                                             "constant directional torque; see run.rolling_moment)"),
    }


# Every parameter, once: nested JSON keys joined by dots. The material section is a `demcal silo --material` file
# (name and description accepted as documentation); the geometry section spells the kernel's --geometry keys.
PARAM_SPECS = {
    "bed_file": text("the kernel's filled bed (demcal silo --export-bed), relative to the run directory"),
    "geometry.shape": text("silo shape (the facet silo is conical)", choices=("conical",), default="conical"),
    "geometry.theta_deg": number("deg", 0.0, 90.0, "hopper half angle from the vertical", lo_open=True, hi_open=True),
    "geometry.outlet_m": number("m", 0.0, 10.0, "outlet diameter d", lo_open=True),
    "geometry.D_m": number("m", 0.0, 10.0, "silo (cylinder) diameter D", lo_open=True),
    "geometry.body_height_m": number("m", 0.0, 100.0, "height of the cylinder above the hopper", lo_open=True),
    "run.stiffness_scale": number("-", 0.0, 100.0, "scales both shear moduli (demcal silo --stiffness-scale)",
                                  lo_open=True),
    "run.time_step_fraction": number("-", 0.0, 1.0, "time step as a fraction of the Rayleigh step of the smallest "
                                     "grain sphere (the kernel's rule)", lo_open=True),
    "run.discharge_time_s": number("s", 0.0, 1e4, "discharge time limit after the opening", lo_open=True),
    "run.sample_interval_s": number("s", 0.0, 10.0, "discharged mass sampled (and grains removed) every ...",
                                    lo_open=True),
    "run.removal_depth_m": number("m", 0.0, 1.0, "a grain counts as discharged when its centre is this far below "
                                  "the outlet (the kernel's default)", default=0.0055, lo_open=True),
    "run.stop_fraction": number("-", 0.0, 1.0, "stop once this fraction of the initial mass has left",
                                default=1.0, lo_open=True),
    "run.stall_time_s": number("s", 0.0, 1e4, "stop when no grain has left for this long (an arch); the kernel: 0.5",
                               default=0.5, lo_open=True),
    "run.facet_segments": number("-", 12, 2000, "facets around the circumference of cone and cylinder",
                                 default=72, integer=True),
    "run.hertzian_facets": number("-", 0, 1, "1: facet contacts with R* = r (the kernel's wall contact, YADE's "
                                  "Ig2_Facet_Sphere_ScGeom.hertzian); 0: YADE's default R* = 2 r / 3",
                                  default=1, integer=True),
    "run.rolling_moment": number("-", 0, 1, "1: YADE's elastic-plastic rolling moment (includeMoment) capped at "
                                 "rolling_friction x (R1 + R2) / 2 x Fn; 0: no rolling resistance. Needs "
                                 "hertzian_facets 0", default=0, integer=True),
    "run.frame_interval_s": number("s", 0.0, 10.0, "flow-pattern frames (the hopper's grains: centre, downward "
                                   "velocity) every ... (the kernel's frame interval); 0: none", default=0.0),
    "run.frames_file": text("if not empty: the flow-pattern frames go to this file (format in FlowFrames; demcal "
                            "classifies them with the kernel's own classifier)", default=""),
    "run.fill": number("-", 0, 1, "0: the bed file holds a filled bed (moment 'opening') and discharges at once; 1: it "
                       "holds the kernel's generated cloud (moment 'generation', demcal silo --export-cloud): YADE "
                       "fills the silo against the closed outlet by the bed's fill rule first", default=0,
                       integer=True),
    "run.readback_file": text("if not empty: write the bed as YADE holds it at t = 0 (before any step) to this file",
                              default=""),
    "run.collider_verlet_dist": number("-", -10.0, 10.0, "InsertionSortCollider.verletDist: bounds enlarged by this "
                                       "(negative: times the smallest radius) so that the collider need not run every "
                                       "step; YADE's default -0.5; 0: the collider runs every step", default=-0.5),
    "run.final_bed_file": text("if not empty: write the grains left when the discharge ends, in the kernel's frame and "
                               "the bed's column layout, with their indices in the bed (demcal silo "
                               "--export-final-bed's counterpart: the same steps from the same bed, compared grain by "
                               "grain)", default=""),
}
for _prefix, _what, _shape in (("material.grain", "grain", True), ("material.wall", "wall", False)):
    PARAM_SPECS.update(solid_specs(_prefix, _what, _shape))
PARAM_SPECS.update(pair_specs("material.grain_grain", "grain-grain"))
PARAM_SPECS.update(pair_specs("material.grain_wall", "grain-wall"))
# Strings that only document (a material file's name and description), never physics.
DOCUMENTATION_KEYS = ("name", "description", "material.name", "material.description")

# --- numerical choices (not inputs; see README.md) ---
# A sampled grain further from the axis than the wall plus this many grain bounding radii went through the wall.
ESCAPE_MARGIN_BOUNDING_RADII = 2.0
# The rolling spring (run.rolling_moment 1) as stiff as the time step allows: the lightest grain's rotation on one
# contact's spring oscillates with a period of this many steps (the kernel's torque acts with no spring at all).
ROLLING_SPRING_PERIOD_STEPS = 60.0
# The steady part of the discharge for the rate: discharged mass between these fractions of the final one (kernel).
STEADY_LOWER, STEADY_UPPER = 0.2, 0.8
# Relative tolerance for the params' geometry against the bed file's.
GEOMETRY_MATCH_TOLERANCE = 1e-9


class RunFailure(Exception):
    def __init__(self, cause, details):
        super().__init__(details)
        self.cause = cause
        self.details = details


def fail(exit_code, cause, details):
    sys.stderr.write("DEMCAL_FAILURE %s: %s\n" % (cause, details.replace("\n", " ")))
    sys.stderr.flush()
    sys.stdout.flush()
    sys.exit(exit_code)


def refuse(field, value, reason):
    fail(2, "params", "%s=%s %s" % (field, json.dumps(value) if not isinstance(value, str) or len(value) < 200
                                     else value[:200], reason))


def flatten(raw, prefix=""):
    """Nested JSON objects to dotted keys; keys starting with '_' are comments."""
    flat = {}
    for key, value in raw.items():
        if key.startswith("_"):
            continue
        name = prefix + key
        if isinstance(value, dict):
            flat.update(flatten(value, name + "."))
        else:
            flat[name] = value
    return flat


def checked_value(key, value, spec):
    if spec["unit"] is None:  # text
        if not isinstance(value, str):
            refuse(key, value, "must be a string (%s)" % spec["meaning"])
        if spec["choices"] is not None and value not in spec["choices"]:
            refuse(key, value, "must be one of %s (%s)" % (", ".join(spec["choices"]), spec["meaning"]))
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        refuse(key, value, "must be a number [%s] (%s)" % (spec["unit"], spec["meaning"]))
    if not math.isfinite(value):
        refuse(key, value, "must be finite")
    if spec["integer"]:
        if value != math.floor(value):
            refuse(key, value, "must be an integer (%s)" % spec["meaning"])
        value = int(value)
    else:
        value = float(value)
    below = value <= spec["lo"] if spec["lo_open"] else value < spec["lo"]
    above = value >= spec["hi"] if spec["hi_open"] else value > spec["hi"]
    if below or above:
        refuse(key, value, "outside %s%g, %g%s %s (%s)" % ("(" if spec["lo_open"] else "[", spec["lo"], spec["hi"],
                                                          ")" if spec["hi_open"] else "]", spec["unit"],
                                                          spec["meaning"]))
    return value


def read_params(path):
    try:
        with open(path) as f:
            raw = json.load(f)
    except OSError as e:
        fail(2, "params", "file=%s cannot be read: %s" % (path, e.strerror))
    except ValueError as e:
        fail(2, "params", "file=%s is not valid JSON: %s" % (path, e))
    if not isinstance(raw, dict):
        fail(2, "params", "file=%s must hold a JSON object" % path)
    params = {}
    for key, value in flatten(raw).items():
        if key in DOCUMENTATION_KEYS:
            if not isinstance(value, str):
                refuse(key, value, "must be a string (documentation field)")
            continue
        if key not in PARAM_SPECS:
            refuse(key, value, "unknown field")
        params[key] = checked_value(key, value, PARAM_SPECS[key])
    for key, spec in PARAM_SPECS.items():
        if key in params:
            continue
        if spec["default"] is REQUIRED:
            refuse(key, "<missing>", "required field%s (%s)" % (" [%s]" % spec["unit"] if spec["unit"] else "",
                                                                spec["meaning"]))
        params[key] = spec["default"]
    for solid in ("material.grain", "material.wall"):
        given = [k for k in (solid + ".shear_modulus_Pa", solid + ".young_Pa") if params[k] is not None]
        if len(given) != 1:
            refuse(solid, "<%s>" % (" and ".join(given) or "neither"),
                   "give exactly one of shear_modulus_Pa and young_Pa (G = E / (2 (1 + nu)))")
    if params["run.rolling_moment"] == 1 and params["run.hertzian_facets"] == 1:
        refuse("run.rolling_moment", 1, "needs run.hertzian_facets 0: with R* = r on facets YADE's rolling cap "
               "eta (R1 + R2) / 2 Fn takes the facet's 1e8 r, so wall contacts would get an uncapped rolling spring")
    return params


def shear_modulus(p, solid):
    g = p.get(solid + ".shear_modulus_Pa")
    return g if g is not None else p[solid + ".young_Pa"] / (2 * (1 + p[solid + ".poisson"]))


def material_values(p):
    """The physical material of flat material.* keys (G whether G or E was given), for comparing two spellings."""
    values = []
    for solid in ("material.grain", "material.wall"):
        values += [shear_modulus(p, solid), p[solid + ".poisson"], p[solid + ".density_kg_m3"]]
    for pair in ("material.grain_grain", "material.grain_wall"):
        values += [p[pair + ".restitution"], p[pair + ".friction"], p[pair + ".rolling_friction"]]
    return values


# ---------------------------------------------------------------------------------------------------- the bed file
def read_bed(path):
    """The bed file, its structure checked; a broken one is refused as a parameter (exit 2) naming bed_file."""
    try:
        with open(path) as f:
            bed = json.load(f)
    except OSError as e:
        refuse("bed_file", path, "cannot be read: %s" % e.strerror)
    except ValueError as e:
        refuse("bed_file", path, "is not valid JSON: %s" % e)
    if not isinstance(bed, dict) or bed.get("schema") != BED_SCHEMA:
        refuse("bed_file", path, "is not a %s file (demcal silo --export-bed writes one)" % BED_SCHEMA)
    try:
        grains = bed["grains"]
        n = int(grains["count"])
        for column, width in (("position_m", 3), ("orientation_wxyz", 4), ("velocity_m_s", 3),
                              ("angular_velocity_rad_s", 3)):
            rows = grains[column]
            if len(rows) != n or any(len(r) != width or not all(math.isfinite(x) for x in r) for r in rows):
                raise ValueError("grains.%s: %d finite rows of %d numbers expected" % (column, n, width))
        members = bed["clump_template"]["members"]
        if not members or any(m["radius_m"] <= 0 or len(m["offset_m"]) != 3 for m in members):
            raise ValueError("clump_template.members: spheres with offset_m [x, y, z] and radius_m > 0 expected")
        for key in ("mass_kg", "density_kg_m3"):
            if not bed["clump_template"][key] > 0:
                raise ValueError("clump_template.%s must be > 0" % key)
        if len(bed["clump_template"]["principal_inertia_kg_m2"]) != 3:
            raise ValueError("clump_template.principal_inertia_kg_m2: 3 numbers expected")
        float(bed["geometry"]["wall_top_m"])
    except (KeyError, TypeError, ValueError) as e:
        refuse("bed_file", path, "is malformed: %s" % e)
    if n < 1:
        refuse("bed_file", path, "holds no grain")
    return bed


def check_bed_geometry(p, bed, path):
    """The grains were filled into the bed's silo: the params must describe that silo."""
    for key in ("shape", "theta_deg", "outlet_m", "D_m", "body_height_m"):
        mine, theirs = p["geometry." + key], bed["geometry"].get(key)
        same = mine == theirs if isinstance(mine, str) else \
            isinstance(theirs, (int, float)) and abs(mine - theirs) <= GEOMETRY_MATCH_TOLERANCE * abs(theirs)
        if not same:
            refuse("geometry." + key, mine, "differs from the bed's %s (bed_file=%s): the grains were filled into "
                   "that silo" % (json.dumps(theirs), path))


# ---------------------------------------------------------------------------------------------------- contact law
def damping_ratio(restitution):
    """YADE's betan/betas giving the kernel's damping: cn = 2 sqrt(5/6) |beta| sqrt(Sn m*), beta(e) of EDEM."""
    if restitution >= 1.0:
        return 0.0
    log_e = math.log(restitution)
    return math.sqrt(5.0 / 6.0) * abs(log_e / math.sqrt(log_e ** 2 + math.pi ** 2))


def kernel_pair_moduli(g1, nu1, g2, nu2):
    """The kernel's (EDEM's) effective moduli of a pair: E* (harmonic) and G* (harmonic in (2 - nu) / G)."""
    e1, e2 = 2 * g1 * (1 + nu1), 2 * g2 * (1 + nu2)
    e_star = 1.0 / ((1 - nu1 ** 2) / e1 + (1 - nu2 ** 2) / e2)
    g_star = 1.0 / ((2 - nu1) / g1 + (2 - nu2) / g2)
    return e_star, g_star


def stiffness_against_kernel(moduli):
    """YADE's Hertz-Mindlin constants of the first grain-grain and grain-facet contacts over the kernel's.

    The kernel: kn coefficient 4/3 E* sqrt(R*), ks coefficient 8 G* sqrt(R*), R* = r1 r2 / (r1 + r2) (a wall: r).
    `moduli`: (E*, G*) of the kernel for "grain_grain" and "grain_wall". Ratios 1 (to 1e-8, the hertzian facet's
    R* = r / (1 + 1e-8)) show the installed YADE mixes the pair as the kernel does; None: no such contact yet.
    """
    ratios = {"grain_grain": None, "grain_wall": None}
    for inter in O.interactions:
        if not inter.isReal:
            continue
        b1, b2 = O.bodies[inter.id1], O.bodies[inter.id2]
        facet = isinstance(b1.shape, Facet) or isinstance(b2.shape, Facet)
        pair = "grain_wall" if facet else "grain_grain"
        if ratios[pair] is not None:
            continue
        if facet:
            r_star = (b2 if isinstance(b1.shape, Facet) else b1).shape.radius
        else:
            r_star = b1.shape.radius * b2.shape.radius / (b1.shape.radius + b2.shape.radius)
        e_star, g_star = moduli[pair]
        ratios[pair] = {"kn": inter.phys.kno / (4.0 / 3.0 * e_star * math.sqrt(r_star)),
                        "ks": inter.phys.kso / (8.0 * g_star * math.sqrt(r_star))}
        if all(v is not None for v in ratios.values()):
            break
    return ratios


def rayleigh_time_step(radius, density, g, nu):
    """The kernel's Rayleigh step: pi r sqrt(rho / G) / (0.1631 nu + 0.8766)."""
    return math.pi * radius * math.sqrt(density / g) / (0.1631 * nu + 0.8766)


# ---------------------------------------------------------------------------------------------------- geometry
def hopper_height(p):
    return (p["geometry.D_m"] - p["geometry.outlet_m"]) / 2.0 / math.tan(math.radians(p["geometry.theta_deg"]))


def ring(radius, z, segments):
    """Vertices of a regular polygon whose mean distance from the axis is `radius` (the facets' area-mean wall)."""
    vertex_radius = radius * (math.pi / segments) / math.sin(math.pi / segments)
    return [Vector3(vertex_radius * math.cos(2 * math.pi * k / segments),
                    vertex_radius * math.sin(2 * math.pi * k / segments), z) for k in range(segments)]


def band_facets(lower, upper, material):
    """Two triangles per side between two rings of equal length: a cone or cylinder band."""
    facets = []
    n = len(lower)
    for k in range(n):
        a, b, c, d = lower[k], lower[(k + 1) % n], upper[(k + 1) % n], upper[k]
        facets.append(utils.facet([a, b, c], material=material))
        facets.append(utils.facet([a, c, d], material=material))
    return facets


def build_silo(p, wall_top, wall_material):
    """Cone (outlet at z = 0) and cylinder up to wall_top from facets; the outlet plate: returns its ids."""
    n = p["run.facet_segments"]
    r_outlet, r_body, hh = p["geometry.outlet_m"] / 2.0, p["geometry.D_m"] / 2.0, hopper_height(p)
    outlet_ring, body_ring, top_ring = ring(r_outlet, 0.0, n), ring(r_body, hh, n), ring(r_body, wall_top, n)
    O.bodies.append(band_facets(outlet_ring, body_ring, wall_material))
    O.bodies.append(band_facets(body_ring, top_ring, wall_material))
    plate = [utils.facet([Vector3(0, 0, 0), outlet_ring[k], outlet_ring[(k + 1) % n]], material=wall_material)
             for k in range(n)]
    return O.bodies.append(plate)


# ---------------------------------------------------------------------------------------------------- grains
def world_inertia_times(q, principal_inertia, w):
    """I_world w for a body of principal moments `principal_inertia` turned by q (body frame -> world)."""
    local = q.conjugate() * w
    return q * Vector3(principal_inertia[0] * local[0], principal_inertia[1] * local[1],
                       principal_inertia[2] * local[2])


def quaternion_wxyz(q):
    return [q[3], q[0], q[1], q[2]]  # minieigen indexes x, y, z, w


class TemplateFrame:
    """YADE's own clump frame of the bed's template, relative to the template's principal frame.

    YADE puts a clump's reference point at ITS centroid of the member spheres and its axes along ITS principal axes
    (appendClumped, discretization 0: the spheres summed) and fixes the members' local positions from them; neither
    can be set from Python. The kernel's centre and axes come from its grid integration of the union: for the wheat
    grain they differ by about 1e-13 m and by the grain's symmetry (a half turn). Built once at the origin in the
    principal frame: `centre` [m] and `orientation` (YADE's body frame -> principal frame) give every grain's YADE
    state from the kernel's, X_yade = X + q centre, q_yade = q orientation, which leaves every sphere exactly where
    the kernel has it; `inertia` is the kernel's principal tensor in YADE's axes (it must be diagonal there).
    """

    def __init__(self, members, grain_material, kernel_inertia):
        clump_id, _ = O.bodies.appendClumped([utils.sphere(offset, radius, material=grain_material)
                                              for offset, radius in members], discretization=0)
        clump = O.bodies[clump_id]
        self.centre = Vector3(clump.state.pos)
        self.orientation = Quaternion(clump.state.ori)
        self.local_positions = sorted(tuple(rel_pos) for rel_pos, _ in clump.shape.members.values())
        O.bodies.erase(clump_id, True)
        axes = self.orientation.toRotationMatrix()  # columns: YADE's axes in the principal frame
        tensor = [[sum(axes[k, i] * kernel_inertia[k] * axes[k, j] for k in range(3)) for j in range(3)]
                  for i in range(3)]
        off_diagonal = max(abs(tensor[i][j]) for i in range(3) for j in range(3) if i != j)
        if off_diagonal > 1e-9 * sum(kernel_inertia):
            raise RunFailure("bed_import", "YADE's principal axes of the template's spheres are not the kernel's "
                             "(off-diagonal inertia %.3g kg m^2 in YADE's axes): the clump's inertia cannot be set"
                             % off_diagonal)
        self.inertia = Vector3(tensor[0][0], tensor[1][1], tensor[2][2])

    def check_same(self, clump):
        """Every clump of the template must get the same frame (it is built the same way)."""
        if sorted(tuple(rel_pos) for rel_pos, _ in clump.shape.members.values()) != self.local_positions:
            raise RunFailure("bed_import", "clump %d got other member positions than the template's frame" % clump.id)


def add_grains(bed, grain_material, grain_density):
    """One rigid clump per bed grain in the kernel's state; returns ([(clump id, mass)], TemplateFrame).

    Each clump is built at the origin in the template's principal frame (so its members' local positions are YADE's
    for the template), then put into the kernel's state through TemplateFrame; mass and inertia are the kernel's
    (its grid integration of the union of the spheres, scaled to this density); the members are placed with YADE's
    rule x_i = X + q r_i. Members get the clump's mass: YADE uses a member's mass only for the contact damping's m*
    (NewtonIntegrator moves members with their clump), and the kernel's m* is that of the clumps.
    """
    template = bed["clump_template"]
    scale = grain_density / template["density_kg_m3"]
    mass = template["mass_kg"] * scale
    members = [(Vector3(*m["offset_m"]), m["radius_m"]) for m in template["members"]]
    frame = TemplateFrame(members, grain_material, [i * scale for i in template["principal_inertia_kg_m2"]])
    grains = bed["grains"]
    clumps = []
    for i in range(grains["count"]):
        clump_id, _ = O.bodies.appendClumped([utils.sphere(offset, radius, material=grain_material)
                                              for offset, radius in members], discretization=0)
        clump = O.bodies[clump_id]
        frame.check_same(clump)
        w, x, y, z = grains["orientation_wxyz"][i]
        q = Quaternion(w, x, y, z)
        com = Vector3(*grains["position_m"][i])
        vel = Vector3(*grains["velocity_m_s"][i])
        spin = Vector3(*grains["angular_velocity_rad_s"][i])
        state = clump.state
        state.pos = com + q * frame.centre
        state.ori = q * frame.orientation
        state.mass = mass
        state.inertia = frame.inertia
        state.vel = vel + spin.cross(state.pos - com)
        state.angVel = spin
        state.angMom = world_inertia_times(state.ori, frame.inertia, spin)  # the aspherical integrator advances this
        for member_id, (local_pos, local_ori) in clump.shape.members.items():
            member = O.bodies[member_id].state
            member.pos = state.pos + state.ori * local_pos
            member.ori = state.ori * local_ori
            member.vel = state.vel + spin.cross(member.pos - state.pos)
            member.angVel = spin
            member.mass = mass
        clumps.append((clump_id, mass))
    return clumps, frame


def state_columns(clump_ids):
    """The clumps' state as YADE holds it (its own frame), in the bed's column layout; sphere_centres_m: YADE's
    members."""
    columns = {"position_m": [], "orientation_wxyz": [], "velocity_m_s": [], "angular_velocity_rad_s": [],
               "sphere_centres_m": []}
    for clump_id in clump_ids:
        state = O.bodies[clump_id].state
        columns["position_m"].append(list(state.pos))
        columns["orientation_wxyz"].append(quaternion_wxyz(state.ori))
        columns["velocity_m_s"].append(list(state.vel))
        columns["angular_velocity_rad_s"].append(list(state.angVel))
        columns["sphere_centres_m"].append([list(O.bodies[m].state.pos) for m in O.bodies[clump_id].shape.members])
    return columns


def in_kernel_frame(columns, frame):
    """YADE's clump states turned back into the kernel's frame of the template: q = q_yade conj(frame orientation),
    X = X_yade - q frame centre, V = V_yade - omega x (q frame centre)."""
    back = dict(columns, position_m=[], orientation_wxyz=[], velocity_m_s=[])
    undo = frame.orientation.conjugate()
    for pos, ori, vel, spin in zip(columns["position_m"], columns["orientation_wxyz"], columns["velocity_m_s"],
                                   columns["angular_velocity_rad_s"]):
        q = Quaternion(*ori) * undo
        arm = q * frame.centre
        back["position_m"].append(list(Vector3(*pos) - arm))
        back["orientation_wxyz"].append(quaternion_wxyz(q))
        back["velocity_m_s"].append(list(Vector3(*vel) - Vector3(*spin).cross(arm)))
    return back


def rotation_between(a, b):
    """Angle [rad] of the rotation from unit quaternion a to b (w, x, y, z); atan2 keeps it exact near 0."""
    w = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
    x = a[0] * b[1] - a[1] * b[0] - a[2] * b[3] + a[3] * b[2]
    y = a[0] * b[2] + a[1] * b[3] - a[2] * b[0] - a[3] * b[1]
    z = a[0] * b[3] - a[1] * b[2] + a[2] * b[1] - a[3] * b[0]
    return 2 * math.atan2(math.sqrt(x * x + y * y + z * z), abs(w))


def import_errors(bed, columns):
    """Largest differences between the bed and YADE's state: centre [m], rotation angle [rad], member centre [m]
    (each YADE member against the nearest of the kernel's spheres of that grain), velocity [m/s], spin [rad/s]."""
    grains = bed["grains"]
    errors = {"position_m": 0.0, "orientation_rad": 0.0, "sphere_centre_m": 0.0, "velocity_m_s": 0.0,
              "angular_velocity_rad_s": 0.0}
    for i in range(grains["count"]):
        for key, column in (("position_m", "position_m"), ("velocity_m_s", "velocity_m_s"),
                            ("angular_velocity_rad_s", "angular_velocity_rad_s")):
            errors[key] = max(errors[key], (Vector3(*grains[column][i]) - Vector3(*columns[column][i])).norm())
        errors["orientation_rad"] = max(errors["orientation_rad"], rotation_between(grains["orientation_wxyz"][i],
                                                                                     columns["orientation_wxyz"][i]))
        kernel_spheres = [Vector3(*c) for c in grains["sphere_centres_m"][i]]
        for centre in columns["sphere_centres_m"][i]:
            nearest = min((Vector3(*centre) - k).norm() for k in kernel_spheres)
            errors["sphere_centre_m"] = max(errors["sphere_centre_m"], nearest)
    return errors


def write_json_atomically(path, data):
    tmp = path + ".tmp%d" % os.getpid()
    with open(tmp, "w") as f:
        json.dump(data, f, indent=1)
        f.write("\n")
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


# ---------------------------------------------------------------------------------------------------- results
def fit_rate(times, masses):
    """Least-squares slope of mass on time over the samples between STEADY_LOWER and STEADY_UPPER of the final
    discharged mass (the kernel's fit_discharge_rate)."""
    final = masses[-1] if masses else 0.0
    window = [(t, m) for t, m in zip(times, masses) if STEADY_LOWER * final <= m <= STEADY_UPPER * final]
    fit = {"ok": False, "window": "discharged mass between %g %% and %g %% of the mass discharged at the end"
                                  % (100 * STEADY_LOWER, 100 * STEADY_UPPER), "samples": len(window)}
    if len(window) < 3 or final <= 0:
        fit["message"] = "fewer than 3 samples in the steady window"
        return fit
    n = float(len(window))
    t_mean = sum(t for t, _ in window) / n
    m_mean = sum(m for _, m in window) / n
    stt = sum((t - t_mean) ** 2 for t, _ in window)
    stm = sum((t - t_mean) * (m - m_mean) for t, m in window)
    smm = sum((m - m_mean) ** 2 for _, m in window)
    if stt <= 0:
        fit["message"] = "the steady window spans no time"
        return fit
    rate = stm / stt
    residual = max(0.0, smm - rate * stm)
    fit.update({"ok": True, "rate_kg_s": rate, "intercept_kg": m_mean - rate * t_mean,
                "rate_se_kg_s": math.sqrt(residual / (n - 2) / stt) if n > 2 else 0.0,
                "r_squared": 1.0 - residual / smm if smm > 0 else 1.0,
                "t_begin_s": window[0][0], "t_end_s": window[-1][0]})
    return fit


# ---------------------------------------------------------------------------------------------------- set-up
class Contact:
    """Materials, time step and Hertz-Mindlin engines set to the kernel's law (README: silo, contact law)."""

    def __init__(self, p, bed):
        self.p = p
        scale = p["run.stiffness_scale"]
        self.g_grain = shear_modulus(p, "material.grain") * scale
        self.g_wall = shear_modulus(p, "material.wall") * scale
        self.nu_grain, self.nu_wall = p["material.grain.poisson"], p["material.wall.poisson"]
        self.rho_grain = p["material.grain.density_kg_m3"]
        self.grain_material = O.materials.append(FrictMat(young=2 * self.g_grain * (1 + self.nu_grain),
                                                          poisson=self.nu_grain, density=self.rho_grain,
                                                          label="grain"))
        self.wall_material = O.materials.append(FrictMat(young=2 * self.g_wall * (1 + self.nu_wall),
                                                         poisson=self.nu_wall,
                                                         density=p["material.wall.density_kg_m3"], label="wall"))
        template = bed["clump_template"]
        self.dt = p["run.time_step_fraction"] * rayleigh_time_step(min(m["radius_m"] for m in template["members"]),
                                                                   self.rho_grain, self.g_grain, self.nu_grain)
        self.rolling = p["run.rolling_moment"] == 1
        lightest_inertia = min(template["principal_inertia_kg_m2"]) * self.rho_grain / template["density_kg_m3"]
        self.rolling_stiffness = lightest_inertia * (2 * math.pi / (ROLLING_SPRING_PERIOD_STEPS * self.dt)) ** 2 \
            if self.rolling else 0.0

    def per_pair(self, value_of_pair):
        """A MatchMaker giving value_of_pair("grain_grain") and value_of_pair("grain_wall") to the two pairs."""
        return MatchMaker(matches=((self.grain_material, self.grain_material, value_of_pair("grain_grain")),
                                   (self.grain_material, self.wall_material, value_of_pair("grain_wall"))))

    def install(self, gravity):
        p = self.p
        damping = self.per_pair(lambda pair: damping_ratio(p["material.%s.restitution" % pair]))
        O.engines = [
            ForceResetter(),
            InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Facet_Aabb()], verletDist=p["run.collider_verlet_dist"]),
            InteractionLoop(
                [Ig2_Sphere_Sphere_ScGeom(), Ig2_Facet_Sphere_ScGeom(hertzian=p["run.hertzian_facets"] == 1)],
                [Ip2_FrictMat_FrictMat_MindlinPhys(
                    frictAngle=self.per_pair(lambda pair: math.atan(p["material.%s.friction" % pair])),
                    betan=damping, betas=damping, krot=self.rolling_stiffness, ktwist=0.0,
                    eta=p["material.grain_grain.rolling_friction"] if self.rolling else 0.0)],
                [Law2_ScGeom_MindlinPhys_Mindlin(includeMoment=self.rolling)]),
            NewtonIntegrator(damping=0.0, gravity=(0, 0, -gravity)),
        ]
        O.dt = self.dt

    def stiffness_check(self):
        return stiffness_against_kernel(
            {"grain_grain": kernel_pair_moduli(self.g_grain, self.nu_grain, self.g_grain, self.nu_grain),
             "grain_wall": kernel_pair_moduli(self.g_grain, self.nu_grain, self.g_wall, self.nu_wall)})

    def summary(self):
        p = self.p
        return {"hertzian_facets": p["run.hertzian_facets"] == 1, "rolling_moment": self.rolling,
                "rolling_stiffness_N_m_rad": self.rolling_stiffness,
                "betan_grain_grain": damping_ratio(p["material.grain_grain.restitution"]),
                "betan_grain_wall": damping_ratio(p["material.grain_wall.restitution"]),
                "facet_segments": p["run.facet_segments"]}


def import_bed(p, bed, contact):
    """The grains into YADE; the import errors, and the readback file when asked for."""
    clumps, frame = add_grains(bed, contact.grain_material, contact.rho_grain)
    columns = state_columns([c for c, _ in clumps])
    errors = import_errors(bed, in_kernel_frame(columns, frame))
    if p["run.readback_file"]:
        write_json_atomically(p["run.readback_file"], {
            "schema": READBACK_SCHEMA, "time_s": O.time, "grains": dict(columns, count=len(clumps)),
            "yade_template_frame": {"centre_m": list(frame.centre),
                                    "orientation_wxyz": quaternion_wxyz(frame.orientation),
                                    "note": "YADE's clump frame in the template's principal frame: kernel q = "
                                            "q_yade conj(orientation), kernel X = X_yade - q centre_m"}})
    print("bed: %d grains imported from %s; largest import errors %s" % (len(clumps), p["bed_file"], errors),
          flush=True)
    return clumps, frame, errors


# ---------------------------------------------------------------------------------------------------- discharge
class DischargeRecord:
    """The discharged mass against time; grains below the removal plane counted and erased (the kernel's rule)."""

    def __init__(self, p, bed, clumps, wall_top, t_open=0.0):
        self.p = p
        self.t_open = t_open  # YADE's time at the opening: the record's times are since then
        self.mass_of = dict(clumps)
        self.grains = len(clumps)
        self.in_silo = set(self.mass_of)
        self.initial_mass = sum(m for _, m in clumps)
        self.removal_z = -p["run.removal_depth_m"]
        members = bed["clump_template"]["members"]
        self.bounding_radius = max(Vector3(*m["offset_m"]).norm() + m["radius_m"] for m in members)
        self.escape_radius = p["geometry.D_m"] / 2.0 + ESCAPE_MARGIN_BOUNDING_RADII * self.bounding_radius
        self.wall_top = wall_top
        self.times, self.masses, self.counts = [0.0], [0.0], [0]
        self.discharged_mass, self.last_out_time = 0.0, 0.0

    def leaving_grains(self):
        """The grains below the removal plane; a grain that is not finite or outside the silo fails the run."""
        leaving = []
        for clump_id in self.in_silo:
            pos = O.bodies[clump_id].state.pos
            if not (math.isfinite(pos[0]) and math.isfinite(pos[1]) and math.isfinite(pos[2])):
                raise RunFailure("nan", "grain %d at %s at t = %.6g s (step %d)" % (clump_id, pos, O.time, O.iter))
            if pos[2] < self.removal_z:
                leaving.append(clump_id)
            elif math.hypot(pos[0], pos[1]) > self.escape_radius or pos[2] > self.wall_top + self.bounding_radius:
                raise RunFailure("escaped", "grain %d at (%.4g, %.4g, %.4g) m is outside the silo at t = %.6g s"
                                 % (clump_id, pos[0], pos[1], pos[2], O.time))
        return leaving

    def now(self):
        return O.time - self.t_open

    def remaining_clumps(self):
        return [(c, self.mass_of[c]) for c in sorted(self.in_silo)]

    def sample(self):
        leaving = self.leaving_grains()
        for clump_id in leaving:
            O.bodies.erase(clump_id, True)  # the clump and its members
            self.in_silo.discard(clump_id)
            self.discharged_mass += self.mass_of[clump_id]
        if leaving:
            self.last_out_time = self.now()
        self.times.append(self.now())
        self.masses.append(self.discharged_mass)
        self.counts.append(self.grains - len(self.in_silo))

    def stop_reason(self):
        """Why the discharge ends now (the kernel's rules), or "" to go on."""
        p = self.p
        if not self.in_silo:
            return "empty"
        if self.discharged_mass >= p["run.stop_fraction"] * self.initial_mass * (1 - 1e-12):
            return "stop fraction %g of the initial mass discharged" % p["run.stop_fraction"]
        if self.now() - self.last_out_time > p["run.stall_time_s"]:
            return "flow stopped: no grain left for %g s, %d grains remain" % (p["run.stall_time_s"],
                                                                               len(self.in_silo))
        if self.now() >= p["run.discharge_time_s"] * (1 - 1e-12):
            return "time limit %g s" % p["run.discharge_time_s"]
        return ""

    def remaining_mass(self):
        return sum(O.bodies[c].state.mass for c in self.in_silo)


class FlowFrames:
    """Flow-pattern frames for the kernel's classifier (kernel/silo/flow_pattern.hpp), which demcal runs on them: the
    measure is computed in one place for both codes. Written while the discharged fraction is at most STEADY_UPPER
    (the classifier's window lies below it), every frame_interval_s of discharge, at the first sample after each due
    time (the kernel's rule, with its sampling interval). Only grains in the hopper (0 < z < hopper height) are kept:
    the classifier looks at no other.

    File (little-endian): the line "demcal.silo_frames/1\n", then per frame: float64 time [s], float64 discharged
    mass [kg], uint32 grain count n, then n x 4 float32: x, y, z [m], vz [m/s]. Written to a temporary file and
    renamed at the end, so a file present is complete."""

    def __init__(self, p, record):
        self.path = p["run.frames_file"]
        self.interval = p["run.frame_interval_s"]
        self.record = record
        self.hopper_height = hopper_height(p)
        self.next_time = 0.0
        self.frames = 0
        self.file = None
        if self.path and self.interval > 0:
            self.tmp = self.path + ".tmp%d" % os.getpid()
            self.file = open(self.tmp, "wb")
            self.file.write((FRAMES_SCHEMA + "\n").encode())

    def sample(self):
        if self.file is None or self.record.now() < self.next_time * (1 - 1e-12):
            return
        self.next_time += self.interval
        if self.record.discharged_mass > STEADY_UPPER * self.record.initial_mass:
            return
        values = array("f")
        for clump_id in self.record.in_silo:
            state = O.bodies[clump_id].state
            if 0.0 < state.pos[2] < self.hopper_height:
                values.extend((state.pos[0], state.pos[1], state.pos[2], state.vel[2]))
        if sys.byteorder != "little":
            values.byteswap()
        self.file.write(struct.pack("<ddI", self.record.now(), self.record.discharged_mass, len(values) // 4))
        values.tofile(self.file)
        self.frames += 1

    def close(self):
        if self.file is None:
            return None
        self.file.flush()
        os.fsync(self.file.fileno())
        self.file.close()
        os.replace(self.tmp, self.path)
        return {"file": self.path, "frames": self.frames, "interval_s": self.interval, "schema": FRAMES_SCHEMA}


def mean_kinetic_energy(clump_ids):
    """Mean kinetic energy per grain, translational and rotational (the kernel's rest measure) [J]."""
    total = 0.0
    for clump_id in clump_ids:
        state = O.bodies[clump_id].state
        spin = state.ori.conjugate() * state.angVel  # in the principal frame, where the inertia is diagonal
        total += 0.5 * state.mass * state.vel.squaredNorm() + 0.5 * sum(state.inertia[k] * spin[k] ** 2
                                                                         for k in range(3))
    return total / len(clump_ids) if clump_ids else 0.0


def fill(p, bed, clumps, contact, wall_top):
    """The kernel's filling from its generated cloud, by the bed's rule: against the closed outlet, record interval
    after record interval, until the mean kinetic energy per grain falls below the rest energy after time_min_s, or
    time_max_s. Grains that fall below the removal plane (through a gap) are lost, as in the kernel. Returns the grains
    left and a summary."""
    rule = bed["fill"]
    record = DischargeRecord(p, bed, clumps, wall_top)
    chunk = max(1, int(round(p["run.sample_interval_s"] / contact.dt)))
    while True:
        O.run(chunk, True)
        lost = record.leaving_grains()
        for clump_id in lost:
            O.bodies.erase(clump_id, True)
            record.in_silo.discard(clump_id)
        energy = mean_kinetic_energy(record.in_silo)
        at_rest = O.time >= rule["time_min_s"] and energy < rule["rest_energy_per_grain_J"]
        if at_rest or O.time >= rule["time_max_s"] * (1 - 1e-12):
            break
    remaining = record.remaining_clumps()
    height = max(O.bodies[c].state.pos[2] for c, _ in remaining) if remaining else 0.0
    summary = {"time_s": O.time, "steps": O.iter, "at_rest": at_rest, "kinetic_energy_per_grain_J": energy,
               "rest_energy_per_grain_J": rule["rest_energy_per_grain_J"], "bed_height_m": height,
               "grains_lost": len(clumps) - len(remaining), "filled_mass_kg": sum(m for _, m in remaining)}
    print("filled: %.4f s, %s, bed height %.4g m, %d grains lost" % (O.time, "at rest" if at_rest else "time limit",
                                                                     height, summary["grains_lost"]), flush=True)
    return remaining, summary


def discharge(p, record, frames, contact):
    """Runs sampling interval after sampling interval until a stop rule holds; returns (stop reason, the stiffness
    check taken once the bed's contacts exist, after the first interval)."""
    chunk = max(1, int(round(p["run.sample_interval_s"] / contact.dt)))
    stiffness = None
    while True:
        O.run(chunk, True)
        record.sample()
        frames.sample()
        if stiffness is None:
            stiffness = contact.stiffness_check()
        reason = record.stop_reason()
        if reason:
            return reason, stiffness
        if len(record.times) % 50 == 0:
            print("t = %.4f s: %d grains discharged, %.4g kg, %d steps" % (O.time, record.counts[-1],
                                                                           record.discharged_mass, O.iter),
                  flush=True)


# ---------------------------------------------------------------------------------------------------- main
def main():
    params_path = sys.argv[1] if len(sys.argv) > 1 else "params.json"
    result_path = sys.argv[2] if len(sys.argv) > 2 else "result.json"
    p = read_params(params_path)
    bed = read_bed(p["bed_file"])
    check_bed_geometry(p, bed, p["bed_file"])
    moment = bed.get("moment", "opening")  # beds written before the cloud export are beds at the opening
    if moment != ("generation" if p["run.fill"] == 1 else "opening"):
        refuse("bed_file", p["bed_file"], "holds the bed at the %s, but run.fill = %d needs %s" % (
            moment, p["run.fill"], "a generated cloud (demcal silo --export-cloud)" if p["run.fill"] == 1
            else "the bed at the opening (demcal silo --export-bed)"))
    if p["run.fill"] == 1:
        rule = bed.get("fill")
        if not isinstance(rule, dict) or not all(isinstance(rule.get(k), (int, float)) and math.isfinite(rule[k])
                                                 and rule[k] >= 0 for k in ("rest_energy_per_grain_J", "time_min_s",
                                                                            "time_max_s")):
            refuse("bed_file", p["bed_file"], "has no valid fill rule (fill.rest_energy_per_grain_J, time_min_s, "
                   "time_max_s)")

    contact = Contact(p, bed)
    contact.install(bed["gravity_m_s2"])
    wall_top = max(bed["geometry"]["wall_top_m"], hopper_height(p) + p["geometry.body_height_m"])
    plate_ids = build_silo(p, wall_top, contact.wall_material)
    clumps, frame, errors = import_bed(p, bed, contact)
    filling = None
    if p["run.fill"] == 1:
        clumps, filling = fill(p, bed, clumps, contact, wall_top)
    # the opening: the plate goes before the first discharge step, as the kernel disables its plate at the opening
    for plate_id in plate_ids:
        O.bodies.erase(plate_id)
    record = DischargeRecord(p, bed, clumps, wall_top, t_open=O.time)
    frames = FlowFrames(p, record)
    stop_reason, stiffness = discharge(p, record, frames, contact)
    frames_written = frames.close()
    if p["run.final_bed_file"]:
        left = [(k, clump_id) for k, (clump_id, _) in enumerate(clumps) if clump_id in record.in_silo]
        write_json_atomically(p["run.final_bed_file"], {
            "schema": READBACK_SCHEMA, "moment": "end", "time_s": O.time, "steps": O.iter,
            "bed_index": [k for k, _ in left],
            "grains": dict(in_kernel_frame(state_columns([c for _, c in left]), frame), count=len(left))})

    fit = fit_rate(record.times, record.masses)
    result = {
        "schema": SCHEMA,
        "curve": {"time_s": record.times, "discharged_mass_kg": record.masses, "grains_discharged": record.counts},
        "rate": fit,
        "initial_mass_kg": record.initial_mass,
        "discharged_mass_kg": record.discharged_mass,
        "remaining_mass_kg": record.remaining_mass(),
        "grains_initial": record.grains,
        "grains_discharged": record.counts[-1],
        "grains_remaining": len(record.in_silo),
        "stop_reason": stop_reason,
        "discharge_time_s": record.now(),
        "fill": filling,
        "import_errors": errors,
        "flow_frames": frames_written,
        "yade_template_frame": {"centre_m": list(frame.centre), "orientation_wxyz": quaternion_wxyz(frame.orientation)},
        "steps": O.iter,  # the filling's too with run.fill 1
        "time_step_s": contact.dt,
        "kernel_time_step_s": bed["time_step_s"],
        "wall_time_s": time.time() - WALL_CLOCK_START,
        "cpu_time_s": time.process_time() - CPU_START,
        "yade_version": str(version),
        "contact_setup": dict(contact.summary(), stiffness_over_kernel=stiffness),
        # False: a deliberate mismatch (another material than the kernel's run): the comparison then measures it
        "material_as_bed": material_values(flatten(bed["material"], "material.")) == material_values(p)
        and bed["stiffness_scale"] == p["run.stiffness_scale"],
    }
    write_json_atomically(result_path, result)
    print("discharged %d of %d grains (%.6g of %.6g kg) in %.4f s (%s); rate %s; %d steps of %.4g s, wall %.1f s"
          % (record.counts[-1], record.grains, record.discharged_mass, record.initial_mass, record.now(), stop_reason,
             "%.6g kg/s" % fit["rate_kg_s"] if fit["ok"] else "not determined (%s)" % fit["message"], O.iter,
             contact.dt, result["wall_time_s"]), flush=True)


try:
    main()
except RunFailure as failure:
    fail(3, failure.cause, failure.details)
