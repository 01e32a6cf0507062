"""What the two probes share: their valid starting inputs, and running one demcal case under a time limit, then
SIGTERM, with the processes it leaves behind found and killed."""
import json
import os
import shutil
import subprocess
import time


def make_fixtures(repo, work):
    """The valid inputs the probes start from, written into `work`: a shear run's params.json (bench/shear's), three
    materials of increasing radius (enlarge), the base material of a stored sensitivity study (calibrate)."""
    shutil.copy(repo + "/bench/shear/logs/params.json", work + "/params.json")
    m = json.load(open(repo + "/examples/materials/sand-tiny.json"))
    for k, (r, E, nu) in enumerate([(2e-3, 5e7, 0.3), (3e-3, 7e7, 0.25), (4e-3, 9e7, 0.21)], 1):
        mm = dict(m)
        mm.update(particle_radius=r, young_modulus=E, poisson_ratio=nu, name="m%d" % k, box_length=0.08,
                  box_width=0.08, box_height=0.04)
        json.dump(mm, open(work + "/E%d.json" % k, "w"))
    study = json.load(open(repo + "/examples/calibration/kernel-sand-bonded-far/sensitivity.json"))
    json.dump(study["base_material"], open(work + "/sens_base.json", "w"))


def tiny_shear_params(repo, normal_stress=5e3, seed=1):
    """A shear run's params.json for examples/materials/sand-tiny.json (its documentation keys left out)."""
    tiny = json.load(open(os.path.join(repo, "examples", "materials", "sand-tiny.json")))
    params = {k: v for k, v in tiny.items() if not k.startswith("_")}
    params.update(normal_stress=normal_stress, seed=seed)
    return params


def small_silo_args(repo):
    """`demcal silo` options of a run of a second or two: 300 grains in the reduced 70 deg hopper, soft, one thread."""
    return ["--geometry", os.path.join(repo, "examples", "silo", "reduced_conical_70deg.json"), "--particles", "300",
            "--stiffness-scale", "0.001", "--fill-time", "0.1", "--max-time", "0.2", "--threads", "1"]


def run_bounded(argv, cwd, limit_s=4, grace_s=20):
    """Runs argv in cwd. Returns (exit code, output, files created in cwd): 124 when it ran past limit_s and stopped on
    SIGTERM, 125 when it did not stop within grace_s more (then killed); output starts with ORPHANS when processes
    whose folder lies in cwd outlived it (they are killed)."""
    before = set(os.listdir(cwd))
    p = subprocess.Popen(argv, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace")
    try:
        out, _ = p.communicate(timeout=limit_s)
        rc = p.returncode
    except subprocess.TimeoutExpired:
        p.terminate()
        try:
            out, _ = p.communicate(timeout=grace_s)
            rc = 124
        except subprocess.TimeoutExpired:
            p.kill()
            out, _ = p.communicate()
            rc, out = 125, "did not stop on SIGTERM within %d s\n" % grace_s + out
        time.sleep(0.5)
        left = []
        for pid in os.listdir("/proc"):
            try:
                if pid.isdigit() and os.readlink("/proc/%s/cwd" % pid).startswith(cwd):
                    left.append(pid)
            except OSError:
                pass
        if left:
            out = "ORPHANS %s after SIGTERM\n" % left + out
            for pid in left:
                try:
                    os.kill(int(pid), 9)
                except OSError:
                    pass
    return rc, out, sorted(set(os.listdir(cwd)) - before)


def setup(argv):
    """The probes' command line (DEMCAL REPO [ONE]) and their scratch folder with the fixtures in it:
    returns (demcal, repo, one or None, scratch folder, fixtures folder)."""
    import tempfile
    demcal, repo = os.path.abspath(argv[1]), os.path.abspath(argv[2])
    work = tempfile.mkdtemp(prefix="demcal-probe-")
    fixtures = work + "/fixtures"
    os.makedirs(fixtures)
    make_fixtures(repo, fixtures)
    return demcal, repo, (argv[3] if len(argv) > 3 else None), work, fixtures


def not_one_line(rc, out):
    """True for a refusal (exit 2) whose output is not one line beginning "demcal: error: " (or, from shear-run, the
    worker's DEMCAL_FAILURE protocol): the README's promise for every refusal."""
    return rc == 2 and (out.strip().count("\n") > 0 or not out.startswith(("demcal: error: ", "DEMCAL_FAILURE ")))
