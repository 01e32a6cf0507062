# -*- coding: utf-8 -*-
"""Runs a YADE script in this YADE process, then removes the process's temporary directory.

Run:  yade -n -j1 -x run_clean.py SCRIPT [ARGS...]     (as `yade -n -j1 -x SCRIPT [ARGS...]` would run it)

Why: YADE 2023.02a creates /tmp/yade-XXXXXX in every process, ignores TMPDIR and leaves the directory behind when
the process ends; a campaign of thousands of runs would leave thousands. The script runs in YADE's own globals (O,
the engines, the functors), sees sys.argv = [SCRIPT, ARGS...] and its exit code passes through unchanged.
"""
import os
import sys

# The first thing a run does once YADE has started: the orchestrator reads a run that failed without this file as a
# simulator that could not start here (YADE's own start failed: no HOME, a broken install), not as the run's failure
# (orchestrator/shear_campaign.cpp, kYadeStartedMarker). Written in the run's folder, YADE's working directory.
open("yade_started", "w").close()


def _remove_yade_temp_dir():
    try:
        directory = os.path.dirname(O.tmpFilename())
        if os.path.basename(directory).startswith("yade-") and not os.listdir(directory):
            os.rmdir(directory)
            print("run_clean: removed YADE's temporary directory %s" % directory, flush=True)
    except Exception:  # a left-over empty directory must never turn a finished run into a failure
        pass


if len(sys.argv) < 2:
    sys.stderr.write("DEMCAL_FAILURE params: run_clean.py needs the script to run as its first argument\n")
    sys.exit(2)
_script = sys.argv[1]
sys.argv = sys.argv[1:]
try:
    with open(_script) as _f:
        _code = compile(_f.read(), _script, "exec")
    exec(_code, globals())
finally:
    _remove_yade_temp_dir()
