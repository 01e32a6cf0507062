#!/usr/bin/env python3
"""Writes the params files of the single-contact reference traces (run once; the JSON files are committed).

Each file is the input of yade_scripts/single_contact.py; see that script's docstring for the meaning of "path".
Units SI; friction_angle in radians. Material values are those of examples/materials/sand.json (and sand-bonded.json
for the bond broken in tension), with a second particle material and a stiffer wall where a case tests pair mixing.
"""
import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
DT = 2e-5  # about 0.5 * utils.PWaveTimeStep() for sand.json (r = 3.5 mm, E = 20 MPa, rho = 2650)


def unit(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def scale(s, v):
    return [s * c for c in v]


def add(*vs):
    return [sum(c) for c in zip(*vs)]


N0 = unit([1.0, 0.4, -0.3])          # direction fixed centre -> moving centre
T1 = unit(cross(N0, [0.0, 0.0, 1.0]))  # tangents
T2 = cross(N0, T1)

SAND = {"type": "CohFrictMat", "young": 2e7, "poisson": 0.3, "density": 2650.0, "friction_angle": math.atan(0.5),
        "normal_cohesion": 30000.0, "shear_cohesion": 30000.0, "is_cohesive": True, "fragile": True,
        "moment_rotation_law": False}
SAND_BONDED = dict(SAND, friction_angle=math.atan(0.4), normal_cohesion=150000.0, shear_cohesion=1e6)
# unbonded particles of two materials (pair mixing: harmonic kn/ks, min friction angle), as the shear box's
# particle material when no bond strength is given (isCohesive=False)
PART_A = dict(SAND, is_cohesive=False)
PART_B = dict(SAND, young=3e7, poisson=0.25, friction_angle=math.atan(0.4), is_cohesive=False)
FRICT_A = {"type": "FrictMat", "young": 2e7, "poisson": 0.3, "density": 2650.0, "friction_angle": math.atan(0.5)}
FRICT_B = dict(FRICT_A, young=3e7, poisson=0.25, friction_angle=math.atan(0.4))
WALL = dict(FRICT_A, young=2.5e7, friction_angle=math.atan(0.45))  # FrictMat like the shear box walls


def seg(steps, vel, angvel=(0.0, 0.0, 0.0)):
    return {"steps": steps, "vel": list(vel), "angvel": list(angvel)}


def sphere_pair(r0, r1, gap):
    return ({"pos": [0.0, 0.0, 0.0], "radius": r0, "material": "a"},
            {"pos": scale(r0 + r1 + gap, N0), "radius": r1, "material": "b"})


def write(name, doc, p):
    p = dict({"_comment": doc}, **p)
    with open(os.path.join(HERE, name + ".json"), "w") as f:
        json.dump(p, f, indent=1)
        f.write("\n")


frict_path = [
    seg(30, scale(-0.05, N0)),                                    # approach: contact from step 5, overlap 25.5 um
    seg(120, scale(0.05, T1)),                                    # slide 120 um along T1: past the Coulomb limit
    seg(60, scale(-0.05, T1), scale(15.0, T2)),                   # slide back while rolling: shear force reverses
    seg(40, scale(0.02, T2), add(scale(40.0, N0), scale(10.0, T1))),  # twist about the normal + sideways
    seg(20, scale(-0.03, N0)),                                    # push in a little more
    seg(60, scale(0.05, N0)),                                     # separate: contact erased when overlap < 0
]
f0, f1 = sphere_pair(0.0035, 0.003, 4.5e-6)
write("ss_frict", "sphere-sphere, unbonded CohFrictPhys + Law2_ScGeom6D_CohFrictPhys_CohesionMoment (the shear box's "
      "particle-particle law when no bond is set); two materials (pair mixing); approach, slide past Coulomb, roll "
      "back, twist, separate", {
          "case": "sphere_sphere", "law": "cohfrict", "dt": DT, "sample_every": 2, "damping": 0.2,
          "materials": {"a": PART_A, "b": PART_B}, "fixed": f0, "moving": f1, "path": frict_path})
write("ss_frict_cundall", "the path of ss_frict with FrictMat particles: FrictPhys + "
      "Law2_ScGeom_FrictPhys_CundallStrack", {
          "case": "sphere_sphere", "law": "frict", "dt": DT, "sample_every": 2, "damping": 0.2,
          "materials": {"a": FRICT_A, "b": FRICT_B}, "fixed": f0, "moving": f1, "path": frict_path})

f0, f1 = sphere_pair(0.0035, 0.003, 4.5e-6)
write("ss_bond_tension", "sphere-sphere, sand-bonded bond set at step 25 (setCohesionNow), slid 25 um while bonded, "
      "then pulled apart at 0.02 m/s until it breaks in tension (-Fn > normalCohesion * min(R)^2) and the contact is "
      "erased", {
          "case": "sphere_sphere", "law": "cohfrict", "dt": DT, "sample_every": 2, "damping": 0.2,
          "bond_at_step": 25, "materials": {"a": SAND_BONDED, "b": SAND_BONDED}, "fixed": f0, "moving": f1,
          "path": [seg(20, scale(-0.05, N0)), seg(10, [0, 0, 0]), seg(25, scale(0.05, T1), scale(5.0, T2)),
                   seg(150, scale(0.02, N0))]})

f0, f1 = sphere_pair(0.0035, 0.0035, 4.5e-6)
write("ss_bond_shear", "sphere-sphere, equal radii, sand bond set at step 22, slid (with spin) until the shear force "
      "passes shearCohesion * min(R)^2 + Fn tan(phi): cohesionBroken, then frictional sliding, then separation", {
          "case": "sphere_sphere", "law": "cohfrict", "dt": DT, "sample_every": 2, "damping": 0.2,
          "bond_at_step": 22, "materials": {"a": SAND, "b": SAND}, "fixed": f0, "moving": f1,
          "path": [seg(20, scale(-0.05, N0)), seg(5, [0, 0, 0]), seg(100, scale(0.05, T1), scale(-8.0, T2)),
                   seg(40, scale(0.05, N0))]})

f0, f1 = sphere_pair(0.0035, 0.003, 4.5e-6)
write("ss_bond_shear_tension", "sphere-sphere, sand bond set at step 12, pulled into tension (not enough to break), "
      "then slid: the bond breaks in shear while Fn < 0 (normal force zeroed in that step, contact erased in the "
      "next), then the spheres are pushed back together: a new, unbonded contact", {
          "case": "sphere_sphere", "law": "cohfrict", "dt": DT, "sample_every": 2, "damping": 0.2,
          "bond_at_step": 12, "materials": {"a": SAND, "b": SAND}, "fixed": f0, "moving": f1,
          "path": [seg(10, scale(-0.05, N0)), seg(4, [0, 0, 0]), seg(40, scale(0.01, N0)), seg(60, scale(0.05, T2)),
                   seg(20, scale(-0.05, N0)), seg(20, scale(-0.05, T2))]})

box = {"center": [0.0, 0.0, -0.002], "extents": [0.01, 0.008, 0.002], "material": "wall"}
write("sb_frict", "sphere (sand CohFrictMat, unbonded) on a fixed utils.box wall (FrictMat, E 25 MPa, friction 0.45): "
      "FrictPhys + Law2_ScGeom_FrictPhys_CundallStrack via Ig2_Box_Sphere_ScGeom; approach the top face, slide with "
      "spin past the Coulomb limit, then slide fast over the box edge until the contact is lost", {
          "case": "sphere_box", "law": "frict", "dt": DT, "sample_every": 2, "damping": 0.2,
          "materials": {"wall": WALL, "b": PART_A}, "fixed": box,
          "moving": {"pos": [0.0095, 0.001, 0.0035 + 4.5e-6], "radius": 0.0035, "material": "b"},
          "path": [seg(30, [0, 0, -0.05]), seg(100, [0.05, 0.02, 0.0], [3.0, 25.0, 8.0]), seg(100, [0.5, 0.0, 0.0])]})

write("sb_dynamic_damped", "a free (dynamic) sand sphere thrown with spin onto the fixed box wall, no gravity, "
      "NewtonIntegrator(damping=0.2): exercises YADE's leapfrog order and the non-viscous local damping", {
          "case": "sphere_box", "law": "frict", "dt": DT, "sample_every": 1, "damping": 0.2, "steps": 60,
          "materials": {"wall": WALL, "b": PART_A}, "fixed": box,
          "moving": {"pos": [0.002, 0.001, 0.0035 + 2.5e-6], "radius": 0.0035, "material": "b", "dynamic": True,
                     "vel0": [0.05, -0.02, -0.1], "angvel0": [5.0, -30.0, 10.0]}})

write("cb_clump_damped", "a free rigid clump of two sand spheres (aspect ratio 1.5: r = 3.5 mm, centres 3.5 mm apart, "
      "appendClumped(discretization=10) as shear_box.py) thrown tilted onto the fixed box wall, no gravity, "
      "NewtonIntegrator(damping=0.2): one member hits first, the clump spins (aspherical integrator, torque damping), "
      "the second member hits while the first is still in contact", {
          "case": "sphere_box", "law": "frict", "dt": DT, "sample_every": 1, "damping": 0.2, "steps": 100,
          "materials": {"wall": WALL, "b": PART_A}, "fixed": box,
          "moving": {"clump": [[0.002, 0.001, 0.0035 + 2.5e-6, 0.0035],
                               [0.002 + 0.0035 * 0.95, 0.001 + 0.0035 * 0.3, 0.0035 + 2.5e-6 + 6e-6, 0.0035]],
                     "material": "b", "vel0": [0.05, -0.02, -0.1]}})

# silo.py's Hertz-Mindlin (Ip2_FrictMat_FrictMat_MindlinPhys, betan = betas; Law2_ScGeom_MindlinPhys_Mindlin) between
# two unlike FrictMat spheres (YADE 2023.02a mixes G* as the kernel does, harmonic in (2 - nu) / G): the kernel's
# YadeHertzMindlin
BETA_E05 = math.sqrt(5.0 / 6.0) * abs(math.log(0.5) / math.sqrt(math.log(0.5) ** 2 + math.pi ** 2))  # silo.py, e = 0.5
f0, f1 = sphere_pair(0.0035, 0.003, 4.5e-6)
write("hm_pair", "sphere-sphere, silo.py's Hertz-Mindlin with viscous damping (betan = betas for e = 0.5), two unlike "
      "FrictMat materials; approach, slide past Coulomb, slide back while rolling, twist, push in, then pull apart so "
      "fast that the damping would pull (YADE clips the normal force at zero) until the contact ends", {
          "case": "sphere_sphere", "law": "mindlin", "betan": BETA_E05, "dt": DT, "sample_every": 1, "damping": 0.0,
          "materials": {"a": FRICT_A, "b": FRICT_B}, "fixed": f0, "moving": f1,
          "path": frict_path[:5] + [seg(40, scale(0.4, N0))]})


# the same law against one of silo.py's wall facets (Ig2_Facet_Sphere_ScGeom, hertzian): a large horizontal triangle at
# z = 0 (normal +z), the sphere above its interior all along the path (no edge contact), the wall's own material
facet = {"vertices": [[-0.05, -0.04, 0.0], [0.06, -0.04, 0.0], [0.0, 0.06, 0.0]], "material": "wall"}
write("hm_facet", "a sphere on one of silo.py's wall facets (utils.facet, Ig2_Facet_Sphere_ScGeom hertzian), silo.py's "
      "Hertz-Mindlin with viscous damping (betan = betas for e = 0.5), the sphere a dynamic body with all DOFs but "
      "the spin about the facet's normal blocked (m* = its mass); approach, slide with spin past Coulomb, slide back rolling, press in, then lift off so "
      "fast that the damping would pull", {
          "case": "sphere_facet", "law": "mindlin", "betan": BETA_E05, "dt": DT, "sample_every": 1, "damping": 0.0,
          "materials": {"wall": WALL, "b": FRICT_A}, "fixed": facet,
          "moving": {"pos": [0.002, 0.001, 0.0035 + 4.5e-6], "radius": 0.0035, "material": "b"},
          "path": [seg(30, [0, 0, -0.05]), seg(100, [0.05, 0.02, 0.0], [3.0, 25.0, 8.0]),
                   seg(60, [-0.05, 0.0, 0.0], [0.0, -15.0, 0.0]), seg(20, [0, 0, -0.03]), seg(40, [0, 0, 0.4])]})
