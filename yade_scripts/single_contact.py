# -*- coding: utf-8 -*-
"""One contact in YADE 2023.02a with the shear box's functors (or, with "law": "mindlin", silo.py's Hertz-Mindlin),
driven along a prescribed path; writes a per-step trace.

Run:  yade -n -j1 -x single_contact.py params.json out.csv
      (or through run_clean.py, as the orchestrator runs shear_box.py, to remove YADE's empty /tmp/yade-XXXXXX)

Writes out.csv (one row per sampled step, every float with 17 significant digits) and out.csv.meta.json (the
parameters, YADE's version, dt, the ids, the interaction's classes, masses). The reference traces, their params files
and the Python reimplementation that reproduces them live in tests/data/yade_contact/ and
yade_scripts/check_single_contact.py; the formulas are in yade_scripts/YADE_LAWS.md.

Bodies: id 0 is the fixed body (a sphere, a box made by utils.box, or a facet made by utils.facet from
fixed.vertices: silo.py's walls, Ig2_Facet_Sphere_ScGeom with hertzian = params "hertzian_facet", default true), id 1
the moving sphere. Both are non-dynamic (dynamic=False: all DOFs blocked), so NewtonIntegrator leaves their
velocities alone and only moves them: pos += vel * dt, the orientation by angVel * dt. (Against a facet the sphere is
a dynamic body with all DOFs but the spin about z blocked instead: it moves the same way, and the Hertz-Mindlin damping
takes its mass as m*, as for a silo grain; a non-dynamic pair would take the facet's zero mass: no damping.) The moving sphere may instead be dynamic ("dynamic": true): it then
starts with vel0/angVel0 and moves under its contact force only (no gravity, NewtonIntegrator damping), which exercises
YADE's integrator and its local damping.

The engines are those of shear_box.py (same Ig2/Ip2/Law2 functors, same order), or with "law": "mindlin" those of
silo.py's grains (Ig2_Sphere_Sphere_ScGeom, Ip2_FrictMat_FrictMat_MindlinPhys with betan = betas = params "betan",
Law2_ScGeom_MindlinPhys_Mindlin), with two PyRunners around them:
  [pre PyRunner, ForceResetter, InsertionSortCollider, InteractionLoop, NewtonIntegrator(damping), post PyRunner]
pre  records the kinematics the InteractionLoop of this step sees (positions x^n, the velocities state.vel/angVel);
post records the interaction (normal, penetration, forces, bond state) and O.forces on both bodies (forces of step n),
     then sets the moving body's velocity for the next step from the path, and arms setCohesionNow so that bonds are
     created in the InteractionLoop of step bond_at_step.

Path (params "path": a list of segments, each {"steps": N, "vel": [vx, vy, vz], "angvel": [wx, wy, wz]}): the segments
are laid end to end; step n (0-based) of the run belongs to the segment that covers it, and that segment's vel/angvel is
the velocity NewtonIntegrator uses in step n to move the moving body from x^n to x^{n+1}. A non-dynamic body's velocity
is never changed by NewtonIntegrator, so the InteractionLoop of step n sees that same velocity: the shear increment of
step n is computed from the move the body is about to make (x^{n+1} - x^n) / dt, while the geometry is that of x^n.
(A dynamic body's InteractionLoop sees v^{n-1/2} = (x^n - x^{n-1}) / dt instead; see YADE_LAWS.md, step order.)
The run lasts sum(steps) steps.
"""
import json
import math
import os
import sys

from yade import utils

REQUIRED = ("case", "law", "dt", "fixed", "moving", "materials", "sample_every")


def fail(msg):
    sys.stderr.write("DEMCAL_FAILURE params: %s\n" % msg)
    sys.exit(2)


def vec(v, name):
    if not (isinstance(v, list) and len(v) == 3 and all(isinstance(c, (int, float)) for c in v)):
        fail("%s=%s must be a list of 3 numbers" % (name, json.dumps(v)))
    return Vector3(float(v[0]), float(v[1]), float(v[2]))


def make_material(spec, name):
    """spec: {"type": "FrictMat"|"CohFrictMat", "young", "poisson", "density", "friction_angle" (rad) [, CohFrictMat keys]}"""
    kind = spec.get("type")
    common = dict(young=float(spec["young"]), poisson=float(spec["poisson"]), density=float(spec["density"]),
                  frictionAngle=float(spec["friction_angle"]), label=name)
    if kind == "FrictMat":
        return O.materials.append(FrictMat(**common))
    if kind == "CohFrictMat":
        return O.materials.append(CohFrictMat(
            normalCohesion=float(spec.get("normal_cohesion", -1)), shearCohesion=float(spec.get("shear_cohesion", -1)),
            isCohesive=bool(spec.get("is_cohesive", True)), fragile=bool(spec.get("fragile", True)),
            momentRotationLaw=bool(spec.get("moment_rotation_law", False)), **common))
    fail("materials.%s.type=%s must be FrictMat or CohFrictMat" % (name, json.dumps(kind)))


def main():
    if len(sys.argv) < 3:
        fail("usage: yade -n -j1 -x single_contact.py params.json out.csv")
    params_path, out_path = sys.argv[1], sys.argv[2]
    with open(params_path) as f:
        p = json.load(f)
    for key in REQUIRED:
        if key not in p:
            fail("%s=<missing> required field" % key)
    if p["case"] not in ("sphere_sphere", "sphere_box", "sphere_facet"):
        fail("case=%s must be sphere_sphere, sphere_box or sphere_facet" % json.dumps(p["case"]))
    if p["case"] == "sphere_facet" and p["law"] != "mindlin":
        fail("law=%s: a sphere_facet case runs silo.py's law, mindlin" % json.dumps(p["law"]))

    mats = {name: make_material(spec, name) for name, spec in p["materials"].items()}
    fixed, moving = p["fixed"], p["moving"]
    if p["case"] == "sphere_sphere":
        b0 = utils.sphere(vec(fixed["pos"], "fixed.pos"), float(fixed["radius"]), material=mats[fixed["material"]],
                          fixed=True)
    elif p["case"] == "sphere_box":
        b0 = utils.box(center=vec(fixed["center"], "fixed.center"), extents=vec(fixed["extents"], "fixed.extents"),
                       fixed=True, material=mats[fixed["material"]])
    else:
        b0 = utils.facet([vec(v, "fixed.vertices[%d]" % k) for k, v in enumerate(fixed["vertices"])],
                         material=mats[fixed["material"]])
    if "clump" in moving:
        return run_clump(p, mats, b0, out_path)
    dynamic = bool(moving.get("dynamic", False))
    # against a facet (mass 0) the sphere must be a dynamic body for the damping's m* to be its mass, as a silo grain
    # against silo.py's walls. YADE's "dynamic" is "not every DOF blocked" (blocking all six makes m* = 0: no damping),
    # so all but the spin about z are blocked: on a horizontal facet the contact's torque has no z component, and the
    # path sets the velocities every step anyway
    blocked = p["case"] == "sphere_facet" and not dynamic
    b1 = utils.sphere(vec(moving["pos"], "moving.pos"), float(moving["radius"]), material=mats[moving["material"]],
                      fixed=not dynamic and not blocked)
    if blocked:
        b1.state.blockedDOFs = "xyzXY"
        assert b1.dynamic
    id0 = O.bodies.append(b0)
    id1 = O.bodies.append(b1)
    assert (id0, id1) == (0, 1)

    path = []  # per-step (vel, angvel) of the moving body
    if not dynamic:
        for k, seg in enumerate(p["path"]):
            v = vec(seg["vel"], "path[%d].vel" % k)
            w = vec(seg.get("angvel", [0, 0, 0]), "path[%d].angvel" % k)
            path.extend([(v, w)] * int(seg["steps"]))
        total_steps = len(path)
        O.bodies[1].state.vel, O.bodies[1].state.angVel = path[0]
    else:
        total_steps = int(p["steps"])
        O.bodies[1].state.vel = vec(moving["vel0"], "moving.vel0")
        O.bodies[1].state.angVel = vec(moving.get("angvel0", [0, 0, 0]), "moving.angvel0")

    bond_at = p.get("bond_at_step")
    cohesive_ip = Ip2_CohFrictMat_CohFrictMat_CohFrictPhys(setCohesionNow=(bond_at == 0), setCohesionOnNewContacts=False)
    if p["law"] == "mindlin":
        # silo.py's Hertz-Mindlin: MindlinPhys with betan = betas, Law2_ScGeom_MindlinPhys_Mindlin (no moment)
        beta = float(p.get("betan", 0.0))
        loop = InteractionLoop(
            [Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom(),
             Ig2_Facet_Sphere_ScGeom(hertzian=bool(p.get("hertzian_facet", True)))],
            [Ip2_FrictMat_FrictMat_MindlinPhys(betan=MatchMaker(algo="val", val=beta),
                                               betas=MatchMaker(algo="val", val=beta))],
            [Law2_ScGeom_MindlinPhys_Mindlin()])
    else:
        loop = InteractionLoop(
            [Ig2_Sphere_Sphere_ScGeom6D(), Ig2_Box_Sphere_ScGeom()],
            [Ip2_FrictMat_FrictMat_FrictPhys(), cohesive_ip],
            [Law2_ScGeom_FrictPhys_CundallStrack(), Law2_ScGeom6D_CohFrictPhys_CohesionMoment()])
    O.engines = [
        PyRunner(iterPeriod=1, initRun=True, command="pre_step()"),
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb(), Bo1_Facet_Aabb()]),
        loop,
        NewtonIntegrator(damping=float(p.get("damping", 0.0)), gravity=Vector3(0, 0, 0)),
        PyRunner(iterPeriod=1, initRun=True, command="post_step()"),
    ]
    O.dt = float(p["dt"])
    sample_every = int(p["sample_every"])

    columns = ["step", "time", "id1", "id2", "real"]
    for b in ("b0", "b1"):
        columns += ["%s_%s%s" % (b, q, c) for q in ("pos_", "vel_", "angvel_") for c in "xyz"]
    columns += ["n_x", "n_y", "n_z", "pen", "cp_x", "cp_y", "cp_z", "kn", "ks", "tan_phi",
                "fn_x", "fn_y", "fn_z", "fs_x", "fs_y", "fs_z", "cohesion_broken", "normal_adhesion", "shear_adhesion"]
    for b in ("b0", "b1"):
        columns += ["%s_%s%s" % (b, q, c) for q in ("f_", "t_") for c in "xyz"]
    rows = []
    pre = {}
    meta = {"phys_class": None, "geom_class": None, "interaction_ids": None, "first_real_step": None,
            "bond_steps": [], "erased_steps": []}

    def fmt(x):
        return repr(float(x))

    def pre_step():
        pre.clear()
        for i, b in ((0, "b0"), (1, "b1")):
            st = O.bodies[i].state
            pre[b] = [st.pos[c] for c in range(3)] + [st.vel[c] for c in range(3)] + [st.angVel[c] for c in range(3)]

    def post_step():
        n = O.iter
        inter = O.interactions[0, 1] if O.interactions.has(0, 1) else None
        real = inter is not None and inter.isReal
        if real:
            if meta["first_real_step"] is None:
                meta["first_real_step"] = n
            meta["phys_class"] = inter.phys.__class__.__name__
            meta["geom_class"] = inter.geom.__class__.__name__
            meta["interaction_ids"] = [inter.id1, inter.id2]
        if meta.get("_was_real") and not real:
            meta["erased_steps"].append(n)
        if real and isinstance(inter.phys, CohFrictPhys) and not inter.phys.cohesionBroken and \
                not meta.get("_was_bonded"):
            meta["bond_steps"].append(n)
        meta["_was_real"] = real
        meta["_was_bonded"] = real and isinstance(inter.phys, CohFrictPhys) and not inter.phys.cohesionBroken
        if n % sample_every == 0 or n == total_steps - 1:
            row = [n, n * O.dt]
            if real:
                row += [inter.id1, inter.id2, 1]
            else:
                row += [-1, -1, 0]
            row += pre["b0"] + pre["b1"]
            if real:
                g, ph = inter.geom, inter.phys
                coh = isinstance(ph, CohFrictPhys)
                row += list(g.normal) + [g.penetrationDepth] + list(g.contactPoint) + [ph.kn, ph.ks, ph.tangensOfFrictionAngle]
                row += list(ph.normalForce) + list(ph.shearForce)
                row += [int(ph.cohesionBroken) if coh else -1, ph.normalAdhesion if coh else 0.0,
                        ph.shearAdhesion if coh else 0.0]
            else:
                row += [0.0] * 16 + [-1, 0.0, 0.0]
            for i in (0, 1):
                row += list(O.forces.f(i)) + list(O.forces.t(i))
            rows.append(row)
        # velocity of the next step (prescribed path), bonds armed for the next step
        if not dynamic and n + 1 < total_steps:
            O.bodies[1].state.vel, O.bodies[1].state.angVel = path[n + 1]
        if bond_at is not None and n + 1 == bond_at:
            cohesive_ip.setCohesionNow = True

    globals()["pre_step"] = pre_step
    globals()["post_step"] = post_step

    O.run(total_steps, True)

    tmp = out_path + ".tmp%d" % os.getpid()
    with open(tmp, "w") as f:
        f.write(",".join(columns) + "\n")
        for row in rows:
            f.write(",".join(str(x) if isinstance(x, int) else fmt(x) for x in row) + "\n")
    os.replace(tmp, out_path)
    st = O.bodies[1].state
    meta = {k: v for k, v in meta.items() if not k.startswith("_")}
    meta.update({"yade_version": str(version), "dt": O.dt, "steps": total_steps, "sample_every": sample_every,
                 "moving_mass": st.mass, "moving_inertia": list(st.inertia), "params": p})
    with open(out_path + ".meta.json", "w") as f:
        json.dump(meta, f, indent=1)
        f.write("\n")
    print("single_contact: %d steps, %d rows -> %s; first real step %s, bonds at %s, erased at %s, phys %s" %
          (total_steps, len(rows), out_path, meta["first_real_step"], meta["bond_steps"], meta["erased_steps"],
           meta["phys_class"]))



def run_clump(p, mats, b0, out_path):
    """A free rigid clump of spheres (O.bodies.appendClumped(..., discretization=10), as shear_box.py makes them) thrown
    with velocity vel0 onto the fixed body; no gravity, NewtonIntegrator(damping). Params: moving = {"clump": [[x, y, z,
    r], ...] (member centres and radii), "material", "vel0"}; "steps". The clump starts without spin (its angular
    momentum is 0); members get the clump's velocity. Ids: 0 fixed body, 1..m members, m+1 the clump.
    One row per sampled step: the clump's kinematics at the start of the step (pos, vel, angVel, angMom, ori as x y z w),
    for each member k its interaction with body 0 (real, pen, normal, normal and shear force) and O.forces on it, and
    O.forces on the clump read after the step (NewtonIntegrator has added the members' sum to it)."""
    moving = p["moving"]
    O.bodies.append(b0)
    members = [utils.sphere(Vector3(m[0], m[1], m[2]), float(m[3]), material=mats[moving["material"]])
               for m in moving["clump"]]
    clump_id, member_ids = O.bodies.appendClumped(members, discretization=10)
    assert member_ids == list(range(1, len(members) + 1)) and clump_id == len(members) + 1
    cs = O.bodies[clump_id].state
    cs.vel = vec(moving["vel0"], "moving.vel0")
    for i in member_ids:
        O.bodies[i].state.vel = cs.vel
    total_steps = int(p["steps"])
    O.engines = [
        PyRunner(iterPeriod=1, initRun=True, command="pre_step()"),
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
        InteractionLoop(
            [Ig2_Sphere_Sphere_ScGeom6D(), Ig2_Box_Sphere_ScGeom()],
            [Ip2_FrictMat_FrictMat_FrictPhys(), Ip2_CohFrictMat_CohFrictMat_CohFrictPhys()],
            [Law2_ScGeom_FrictPhys_CundallStrack(), Law2_ScGeom6D_CohFrictPhys_CohesionMoment()]),
        NewtonIntegrator(damping=float(p.get("damping", 0.0)), gravity=Vector3(0, 0, 0)),
        PyRunner(iterPeriod=1, initRun=True, command="post_step()"),
    ]
    O.dt = float(p["dt"])
    sample_every = int(p["sample_every"])
    columns = ["step", "time"] + ["c_%s%s" % (q, c) for q in ("pos_", "vel_", "angvel_", "angmom_") for c in "xyz"] + \
        ["c_ori_%s" % c for c in "xyzw"]
    for k in range(1, len(members) + 1):
        columns += ["m%d_%s" % (k, q) for q in ("real", "pen", "n_x", "n_y", "n_z", "fn_x", "fn_y", "fn_z", "fs_x",
                                                "fs_y", "fs_z", "f_x", "f_y", "f_z", "t_x", "t_y", "t_z")]
    columns += ["c_f_x", "c_f_y", "c_f_z", "c_t_x", "c_t_y", "c_t_z"]
    rows, pre = [], []

    def pre_step():
        del pre[:]
        pre.extend(list(cs.pos) + list(cs.vel) + list(cs.angVel) + list(cs.angMom) +
                   [cs.ori[0], cs.ori[1], cs.ori[2], cs.ori[3]])

    def post_step():
        n = O.iter
        if not (n % sample_every == 0 or n == total_steps - 1):
            return
        row = [n, n * O.dt] + pre
        for i in member_ids:
            inter = O.interactions[0, i] if O.interactions.has(0, i) else None
            if inter is not None and inter.isReal:
                assert (inter.id1, inter.id2) == (0, i)
                row += [1, inter.geom.penetrationDepth] + list(inter.geom.normal) + list(inter.phys.normalForce) + \
                    list(inter.phys.shearForce)
            else:
                row += [0] + [0.0] * 10
            row += list(O.forces.f(i)) + list(O.forces.t(i))
        row += list(O.forces.f(clump_id)) + list(O.forces.t(clump_id))
        rows.append(row)

    globals()["pre_step"] = pre_step
    globals()["post_step"] = post_step
    sub = O.bodies[clump_id].shape.members
    meta = {"yade_version": str(version), "dt": O.dt, "steps": total_steps, "sample_every": sample_every,
            "clump_id": clump_id, "member_ids": member_ids, "clump_mass": cs.mass, "clump_inertia": list(cs.inertia),
            "clump_pos0": list(cs.pos), "clump_ori0": [cs.ori[0], cs.ori[1], cs.ori[2], cs.ori[3]],
            "clump_aspherical": O.bodies[clump_id].aspherical,
            "member_local_pos": [list(sub[i][0]) for i in member_ids],
            "member_mass": [O.bodies[i].state.mass for i in member_ids], "params": p}
    O.run(total_steps, True)
    tmp = out_path + ".tmp%d" % os.getpid()
    with open(tmp, "w") as f:
        f.write(",".join(columns) + "\n")
        for row in rows:
            f.write(",".join(str(x) if isinstance(x, int) else repr(float(x)) for x in row) + "\n")
    os.replace(tmp, out_path)
    with open(out_path + ".meta.json", "w") as f:
        json.dump(meta, f, indent=1)
        f.write("\n")
    print("single_contact: clump of %d, %d steps, %d rows -> %s" % (len(members), total_steps, len(rows), out_path))


main()
