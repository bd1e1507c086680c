#!/usr/bin/env python3
"""Run NC programs on LinuxCNC's own planner, before and after polepatch (issue 31).

Builds a headless LinuxCNC simulation configuration from a polepatch machine (a TOML file
or a built-in name): `xyzac-trt-kins` or `xyzbc-trt-kins` (always TCP) with the machine's
velocity and acceleration limits on every axis and joint, the servo period its Tcy, G64
blending without tolerance, and `[FILTER]` set to `polepatch filter` for `.ngc` files. The
"display" is this same file (`--driver`): it drives LinuxCNC through the `linuxcnc`
Python module as LinuxCNC's own tests do, runs the program's `[FILTER]` exactly as the
AXIS GUI does (`sh -c "FILTER 'file'"`, standard output loaded, `FILTER_PROGRESS=N` read
from standard error, a non-zero exit refused), runs it, and records:

- the cycle time (from the run command to the end of motion, polled every ms),
- the time the planner spends on given program lines (a near-pole run's blocks), counted
  in HAL each servo period from `motion.program-line` (the line of the segment moving
  fastest),
- the time line of `motion_line` (polled),
- the peak joint velocities and accelerations, from HAL (`ddt` twice on each joint's
  commanded position, `minmax` on each).

Usage (from the repository root, LinuxCNC installed: `apt-get install linuxcnc-uspace`):

    /usr/bin/python3 benches/linuxcnc/lcnc_bench.py run PROGRAM --machine M [--filter] [--json OUT]
    /usr/bin/python3 benches/linuxcnc/lcnc_bench.py table [--out docs/validation-linuxcnc.json]
    /usr/bin/python3 benches/linuxcnc/lcnc_bench.py print OUT.json    # the tables again
    /usr/bin/python3 benches/linuxcnc/lcnc_bench.py convert PROGRAM   # LinuxCNC syntax on stdout

`run` prints one JSON document; `table` runs the quality suite's programs (converted to
LinuxCNC syntax), before and after, next to `polepatch analyze`, `simulate` and
`simulate --planner linuxcnc`, and prints the Markdown table of docs/validation.md.
The polepatch binary is $POLEPATCH (default target/release/polepatch).
"""

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
MACHINES = os.path.join(ROOT, "crates", "kinematics", "machines")

# ---------------------------------------------------------------------------------------
# Machines


def load_machine(name):
    """(TOML text, parsed dict) of a built-in name or a TOML file."""
    import tomllib

    path = name if os.path.exists(name) else os.path.join(MACHINES, name + ".toml")
    with open(path, "rb") as f:
        text = f.read().decode()
    return text, tomllib.loads(text)


def limits(m):
    """Per axis X Y Z P C: (velocity, acceleration) in mm/s, mm/s², °/s, °/s²."""
    out = []
    for key in ("x", "y", "z"):
        a = m[key]
        out.append((a["v_m_min"] * 1000.0 / 60.0, a["a_m_s2"] * 1000.0))
    for key in ("primary", "c"):
        a = m[key]
        out.append((a["v_rpm"] * 6.0, a["a_rev_s2"] * 360.0))
    return out


def tcp_machine_toml(name, workdir):
    """The machine as a TOML file whose controller is always TCP (LinuxCNC's
    xyzac-trt-kins / xyzbc-trt-kins: X Y Z are workpiece coordinates, no TCPM code)."""
    text, m = load_machine(name)
    if "controller" not in m:
        text += "\n[controller]\ntcpm_always = true\n"
    path = os.path.join(workdir, m["name"] + "-linuxcnc.toml")
    with open(path, "w") as f:
        f.write(text)
    return path


INI = """# Written by benches/linuxcnc/lcnc_bench.py from the polepatch machine {name}
[EMC]
VERSION = 1.1
MACHINE = polepatch-{name}
DEBUG = 0

[DISPLAY]
DISPLAY = {driver}
CYCLE_TIME = 0.010
POSITION_OFFSET = RELATIVE
POSITION_FEEDBACK = ACTUAL
MAX_FEED_OVERRIDE = 1.0

[FILTER]
PROGRAM_EXTENSION = .ngc polepatch: patch the rotary words near the pole
{filter}

[RS274NGC]
PARAMETER_FILE = sim.var
RS274NGC_STARTUP_CODE = G17 G21 G40 G49 G80 G90 G94 G64

[EMCMOT]
EMCMOT = motmod
SERVO_PERIOD = {period_ns}
COMM_TIMEOUT = 1.0

[TASK]
TASK = milltask
CYCLE_TIME = 0.001

[HAL]
HALFILE = sim.hal

[TRAJ]
COORDINATES = {coords}
LINEAR_UNITS = mm
ANGULAR_UNITS = degree
DEFAULT_LINEAR_VELOCITY = {vlin}
MAX_LINEAR_VELOCITY = {vlin}
DEFAULT_LINEAR_ACCELERATION = {alin}
MAX_LINEAR_ACCELERATION = {alin}
POSITION_FILE = position.txt

[EMCIO]
EMCIO = io
CYCLE_TIME = 0.100
TOOL_TABLE = sim.tbl

[KINS]
KINEMATICS = {kins}
JOINTS = 5
"""

AXIS = """
[AXIS_{letter}]
MIN_LIMIT = {lo}
MAX_LIMIT = {hi}
MAX_VELOCITY = {v}
MAX_ACCELERATION = {a}

[JOINT_{j}]
TYPE = {type}
HOME = 0
MIN_LIMIT = {lo}
MAX_LIMIT = {hi}
MAX_VELOCITY = {v}
MAX_ACCELERATION = {a}
HOME_SEARCH_VEL = 0
HOME_SEQUENCE = 0
"""

HAL = """# Written by benches/linuxcnc/lcnc_bench.py: joints loop back, peaks recorded
loadrt [KINS]KINEMATICS
loadrt [EMCMOT]EMCMOT servo_period_nsec=[EMCMOT]SERVO_PERIOD num_joints=[KINS]JOINTS
loadrt ddt count=10
loadrt minmax count=10
loadrt integ count={integs}
loadrt comp count=1
loadrt conv_bit_float count={bits}
addf motion-command-handler servo-thread
addf motion-controller servo-thread
# The planner's own clock (integ.1: servo periods, whatever the wall clock does on a busy
# machine) and the time it spends moving (integ.0: periods with a non-zero speed).
setp integ.1.in 1
setp comp.0.in0 0.000000001
net speed motion.current-vel => comp.0.in1
net moving comp.0.out => conv-bit-float.0.in
net moving-f conv-bit-float.0.out => integ.0.in
addf comp.0 servo-thread
addf conv-bit-float.0 servo-thread
addf integ.0 servo-thread
addf integ.1 servo-thread
"""


def write_config(machine, workdir, polepatch, with_filter, windows=()):
    """Write the INI, HAL, tool table and variable file; return the INI's path.
    `windows`: (first, last) program lines whose time the planner spends on is counted in
    HAL (`motion.program-line` in the window, each servo period)."""
    _, m = load_machine(machine)
    lim = limits(m)
    letter = m["primary"]["letter"].upper()
    kins = {"A": "xyzac-trt-kins", "B": "xyzbc-trt-kins"}[letter]
    toml = tcp_machine_toml(machine, workdir)
    filt = (
        "ngc = {} filter --machine {}".format(polepatch, toml) if with_filter else ""
    )
    vlin = max(v for v, _ in lim[:3])
    alin = max(a for _, a in lim[:3])
    # LinuxCNC runs DISPLAY as `PROGRAM -ini FILE`: a wrapper that runs this file's driver
    # with the Python that has the `linuxcnc` module.
    driver = os.path.join(workdir, "driver.sh")
    with open(driver, "w") as f:
        f.write('#!/bin/sh\nexec %s %s --driver "$@"\n' % (sys.executable, os.path.abspath(__file__)))
    os.chmod(driver, 0o755)
    text = INI.format(
        name=m["name"],
        driver=driver,
        filter=filt,
        period_ns=int(round(m.get("tcy_ms", 1.0) * 1e6)),
        coords="XYZ" + letter + "C",
        vlin=vlin,
        alin=alin,
        kins=kins,
    )
    lo_p, hi_p = m["primary"].get("range_deg", [-120.0, 120.0])
    for j, (axis, (v, a)) in enumerate(zip("XYZ" + letter + "C", lim)):
        if j < 3:
            lo, hi, typ = -100000.0, 100000.0, "LINEAR"
        elif j == 3:
            lo, hi, typ = lo_p, hi_p, "ANGULAR"
        else:
            lo, hi, typ = -1e7, 1e7, "ANGULAR"
        text += AXIS.format(letter=axis, j=j, lo=lo, hi=hi, v=v, a=a, type=typ)
    with open(os.path.join(workdir, "sim.ini"), "w") as f:
        f.write(text)
    n = len(windows)
    hal = HAL.format(integs=2 + n, bits=1 + n)
    for j in range(5):
        hal += (
            "net j{j} joint.{j}.motor-pos-cmd => joint.{j}.motor-pos-fb ddt.{j}.in\n"
            "net v{j} ddt.{j}.out => ddt.{k}.in minmax.{j}.in\n"
            "net a{j} ddt.{k}.out => minmax.{k}.in\n"
            "addf ddt.{j} servo-thread\naddf ddt.{k} servo-thread\n"
            "addf minmax.{j} servo-thread\naddf minmax.{k} servo-thread\n"
        ).format(j=j, k=j + 5)
    if windows:
        # Window k: wcomp.k → conv-bit-float.(k+1) → integ.(k+2).
        hal += (
            "loadrt conv_s32_float count=1\nloadrt wcomp count={n}\n"
            "net pline motion.program-line => conv-s32-float.0.in\n"
            "addf conv-s32-float.0 servo-thread\n"
        ).format(n=n)
        hal += "net plinef conv-s32-float.0.out => %s\n" % " ".join(
            "wcomp.%d.in" % k for k in range(n)
        )
        for k, (lo, hi) in enumerate(windows):
            hal += (
                "setp wcomp.{k}.min {lo}\nsetp wcomp.{k}.max {hi}\n"
                "net win{k} wcomp.{k}.out => conv-bit-float.{b}.in\n"
                "net win{k}f conv-bit-float.{b}.out => integ.{i}.in\n"
                "addf wcomp.{k} servo-thread\naddf conv-bit-float.{b} servo-thread\n"
                "addf integ.{i} servo-thread\n"
            ).format(k=k, b=k + 1, i=k + 2, lo=lo - 0.5, hi=hi + 0.5)
    hal += (
        "net estop-loop iocontrol.0.user-enable-out => iocontrol.0.emc-enable-in\n"
        "net tool-prep-loop iocontrol.0.tool-prepare => iocontrol.0.tool-prepared\n"
        "net tool-change-loop iocontrol.0.tool-change => iocontrol.0.tool-changed\n"
    )
    with open(os.path.join(workdir, "sim.hal"), "w") as f:
        f.write(hal)
    with open(os.path.join(workdir, "sim.tbl"), "w") as f:
        for t in range(1, 100):
            f.write("T{0} P{0} Z0 D6 ;\n".format(t))
    open(os.path.join(workdir, "sim.var"), "w").close()
    return os.path.join(workdir, "sim.ini")


# ---------------------------------------------------------------------------------------
# Programs in LinuxCNC syntax


def convert(data):
    """A Heidenhain ISO, Fanuc or Sinumerik program of the quality suite in LinuxCNC
    syntax, line for line (a line that has no LinuxCNC meaning is left empty, so line
    numbers stay those of the source): block numbers kept, `*` and `+` signs dropped,
    `;` comments dropped, `A=1.5` → `A1.5`, Sinumerik's G71/G70 → G21/G20; TCPM codes dropped (the kinematics are always
    TCP); `%` and `O` lines, the Heidenhain datum `G54 X Y Z`, program stops, Sinumerik
    frames, cycles and messages dropped; a Sinumerik tool name → T1; M13 → M3 M8; M2 added if no program end."""
    text = data.decode("latin-1")
    out = []
    ended = False
    # Sinumerik's G71/G70 are metric/inch (LinuxCNC's G70/G71 are lathe cycles).
    sinumerik = re.search(r"\b(TRAORI|TRAFOOF)\b", text.upper()) is not None
    for raw in text.splitlines():
        line = raw.split(";", 1)[0].rstrip()
        line = line.rstrip("*").rstrip()
        s = line.strip()
        u = s.upper()
        if (
            not s
            or "%" in s
            or re.match(r"^O\d+", u)
            or re.search(r"\b(TRAORI|TRAFOOF|CYCLE800|MSG|M128|M129|M0?0|M0?1)\b", u)
            or re.search(r"\bG54\s+[XYZ]", u)
        ):
            out.append("")
            continue
        s = re.sub(r"\bG43\.4\s*H\d+", "", s, flags=re.I)
        s = re.sub(r'T="[^"]*"', "T1", s)
        s = re.sub(r"\bD\d+\b", "", s)
        s = re.sub(r"([A-Z])\s*=\s*", r"\1", s)
        s = re.sub(r"([A-Z])\+", r"\1", s)
        s = re.sub(r"\bM13\b", "M3 M8", s)
        if sinumerik:
            s = re.sub(r"\bG71\b", "G21", s)
            s = re.sub(r"\bG70\b", "G20", s)
        if re.search(r"\bM(0?2|30)\b", s.upper()):
            ended = True
        out.append(s.strip())
    if not ended:
        out.append("M2")
    return ("\n".join(out) + "\n").encode()


# ---------------------------------------------------------------------------------------
# The driver (LinuxCNC's DISPLAY)

PROGRESS = re.compile(r"^FILTER_PROGRESS=(\d*)$")
# The end of a program: idle and at rest this long, s of the planner's clock.
END_SETTLE_S = 0.5


def run_filter(program_filter, infile, outfile):
    """AXIS's `filter_program`: (exit code, standard error less the progress lines,
    progress values seen)."""
    q = infile.replace("'", "'\\''")
    env = dict(os.environ)
    env["AXIS_PROGRESS_BAR"] = "1"
    with open(outfile, "w") as out:
        p = subprocess.Popen(
            ["sh", "-c", "%s '%s'" % (program_filter, q)],
            stdin=subprocess.PIPE,
            stdout=out,
            stderr=subprocess.PIPE,
            env=env,
        )
        p.stdin.close()
        err, progress = [], []
        for line in p.stderr:
            line = line.decode()
            m = PROGRESS.match(line)
            if m:
                progress.append(int(m.group(1)))
            else:
                err.append(line)
        p.wait()
    return p.returncode, "".join(err), progress


def driver():
    import hal
    import linuxcnc

    out_path = os.environ["LCNC_BENCH_OUT"]
    program = os.environ["LCNC_BENCH_PROGRAM"]
    ini_path = sys.argv[sys.argv.index("-ini") + 1]
    result = {"program": program, "error": None}

    def finish():
        with open(out_path, "w") as f:
            json.dump(result, f)

    try:
        ini = linuxcnc.ini(ini_path)
        c, s, e = linuxcnc.command(), linuxcnc.stat(), linuxcnc.error_channel()

        def wait(pred, timeout, what):
            t_end = time.monotonic() + timeout
            while time.monotonic() < t_end:
                s.poll()
                if pred():
                    return
                time.sleep(0.005)
            raise RuntimeError("timed out waiting for " + what)

        wait(lambda: s.task_state != 0, 30, "task")
        c.state(linuxcnc.STATE_ESTOP_RESET)
        c.state(linuxcnc.STATE_ON)
        wait(lambda: s.task_state == linuxcnc.STATE_ON, 10, "machine on")
        c.mode(linuxcnc.MODE_MANUAL)
        c.home(-1)
        wait(lambda: all(s.homed[j] for j in range(5)), 30, "homing")
        # The [FILTER] of the program's extension, as AXIS runs it.
        ext = os.path.splitext(program)[1][1:]
        program_filter = ini.find("FILTER", ext)
        to_open = program
        if program_filter:
            to_open = os.path.join(os.path.dirname(out_path), "filtered-" + os.path.basename(program))
            t0 = time.monotonic()
            code, err, progress = run_filter(program_filter, program, to_open)
            result["filter"] = {
                "command": program_filter,
                "exit": code,
                "stderr": err,
                "progress": progress,
                "seconds": time.monotonic() - t0,
            }
            if code:
                result["error"] = "filter failed with exit %d: %s" % (code, err)
                return
        c.mode(linuxcnc.MODE_AUTO)
        c.wait_complete()
        c.program_open(to_open)
        c.wait_complete()
        for k in range(10):
            subprocess.run(["halcmd", "setp", "minmax.%d.reset" % k, "1"], check=True)
        time.sleep(0.01)
        for k in range(10):
            subprocess.run(["halcmd", "setp", "minmax.%d.reset" % k, "0"], check=True)
        # Times in servo periods (HAL's integ), not the wall clock: on a busy machine a
        # non-realtime servo thread runs late, but each cycle is one period of the planner.
        comp = hal.component("polepatch-bench")  # hal.get_value needs a component
        comp.ready()
        clock = lambda: hal.get_value("integ.1.out")
        moving0 = hal.get_value("integ.0.out")
        nwin = len(json.loads(os.environ.get("LCNC_BENCH_WINDOWS", "[]")))
        win0 = [hal.get_value("integ.%d.out" % (k + 2)) for k in range(nwin)]
        timeline = []
        last = None
        t_start = clock()
        wall0 = time.monotonic()
        c.auto(linuxcnc.AUTO_RUN, 0)
        deadline = wall0 + float(os.environ.get("LCNC_BENCH_TIMEOUT", "1800"))
        t_end = None
        # The program has started once the interpreter leaves IDLE (on a busy machine task
        # may take a while to act on the run command).
        started = False
        while time.monotonic() < deadline:
            s.poll()
            now = clock() - t_start
            if not started:
                started = s.interp_state != linuxcnc.INTERP_IDLE
                if not started and time.monotonic() - wall0 > 30:
                    result["error"] = "the program did not start within 30 s"
                    break
            if s.motion_line != last:
                last = s.motion_line
                timeline.append([now, last])
            msg = e.poll()
            if msg and msg[0] in (linuxcnc.NML_ERROR, linuxcnc.OPERATOR_ERROR):
                result["error"] = "LinuxCNC: " + msg[1]
                break
            # Done once idle with nothing queued and at rest for END_SETTLE_S of the
            # planner's time (a momentary stop while task is busy is not the end).
            idle = (
                started
                and s.interp_state == linuxcnc.INTERP_IDLE
                and s.exec_state == linuxcnc.EXEC_DONE
                and s.queue == 0
                and s.current_vel == 0
            )
            if not idle:
                t_end = None
            elif t_end is None:
                t_end = now
            elif now - t_end > END_SETTLE_S:
                break
            time.sleep(0.0005)
        else:
            result["error"] = "timed out"
        result["cycle_time_s"] = hal.get_value("integ.0.out") - moving0
        result["window_times_s"] = [
            hal.get_value("integ.%d.out" % (k + 2)) - w for k, w in enumerate(win0)
        ]
        result["run_to_idle_s"] = t_end
        result["wall_s"] = time.monotonic() - wall0
        result["timeline"] = timeline
        peaks = []
        for k in range(10):
            vals = []
            for pin in ("max", "min"):
                r = subprocess.run(
                    ["halcmd", "getp", "minmax.%d.%s" % (k, pin)],
                    capture_output=True,
                    text=True,
                    check=True,
                )
                vals.append(abs(float(r.stdout.strip())))
            peaks.append(max(vals))
        result["peak_joint_velocity"] = peaks[:5]
        result["peak_joint_acceleration"] = peaks[5:]
    except Exception as ex:  # reported in the result, never lost
        result["error"] = "%s: %s" % (type(ex).__name__, ex)
    finally:
        finish()


# ---------------------------------------------------------------------------------------
# Runs


def polepatch_bin():
    return os.environ.get("POLEPATCH") or os.path.join(ROOT, "target", "release", "polepatch")


def run_program(program, machine, with_filter, windows=(), timeout_s=1800):
    """Run `program` (LinuxCNC syntax) in a fresh headless LinuxCNC; the driver's result.
    `windows`: (first, last) program lines to time (`window_times_s`)."""
    if shutil.which("linuxcnc") is None:
        raise RuntimeError("LinuxCNC is not installed (apt-get install linuxcnc-uspace)")
    workdir = tempfile.mkdtemp(prefix="polepatch-lcnc-")
    try:
        ini = write_config(machine, workdir, polepatch_bin(), with_filter, windows)
        prog = os.path.join(workdir, os.path.basename(program))
        if not prog.endswith(".ngc"):
            prog += ".ngc"
        shutil.copyfile(program, prog)
        out = os.path.join(workdir, "result.json")
        env = dict(os.environ)
        if os.geteuid() == 0 and "RTAPI_UID" not in env:
            # LinuxCNC's realtime refuses root without a fallback user (CI runs as root).
            # Its realtime process then runs as `nobody`, with its FIFO where that user
            # may write.
            env["RTAPI_UID"] = str(65534)
            fifo_dir = os.path.join(workdir, "rtapi")
            os.mkdir(fifo_dir)
            os.chmod(fifo_dir, 0o777)
            os.chmod(workdir, 0o755)
            env["RTAPI_FIFO_PATH"] = os.path.join(fifo_dir, "fifo")
        env.update(
            LCNC_BENCH_WINDOWS=json.dumps(list(windows)),
            LCNC_BENCH_OUT=out,
            LCNC_BENCH_PROGRAM=prog,
            LCNC_BENCH_TIMEOUT=str(timeout_s),
        )
        log = os.path.join(workdir, "linuxcnc.log")
        with open(log, "w") as f:
            p = subprocess.run(
                ["linuxcnc", ini],
                cwd=workdir,
                env=env,
                stdout=f,
                stderr=subprocess.STDOUT,
                stdin=subprocess.DEVNULL,
                timeout=timeout_s + 120,
            )
        if not os.path.exists(out):
            with open(log) as f:
                tail = f.read()[-3000:]
            raise RuntimeError("LinuxCNC exited %d without a result:\n%s" % (p.returncode, tail))
        with open(out) as f:
            result = json.load(f)
        result["machine"] = machine
        return result
    finally:
        if not os.environ.get("LCNC_BENCH_KEEP"):
            shutil.rmtree(workdir, ignore_errors=True)


# ---------------------------------------------------------------------------------------
# The table of docs/validation.md

SUITE = [
    ("fixtures/c17/SING.I", "mikron-ucp710"),
    ("fixtures/c17/NON_SING.I", "mikron-ucp710"),
    ("fixtures/dialects/fanuc.nc", "mikron-ucp710"),
    ("fixtures/dialects/heidenhain_latin1.I", "mikron-ucp710"),
    ("fixtures/dialects/sinumerik.mpf", "mikron-ucp710"),
] + [
    ("fixtures/generated/heidenhain-%s-%s-%s.I" % (m, k, d), mach)
    for m, mach in (("ac", "mikron-ucp710"), ("bc", "mikron-hsm600"))
    for k in ("flip", "swing")
    for d in ("d0.1", "d1")
]


def pp_json(args):
    r = subprocess.run([polepatch_bin()] + args, capture_output=True, check=True)
    return json.loads(r.stdout)


def table(out_json):
    rows = []
    work = tempfile.mkdtemp(prefix="polepatch-validation-")
    for src, machine in SUITE:
        name = os.path.splitext(os.path.basename(src))[0]
        before = os.path.join(work, name + ".ngc")
        with open(os.path.join(ROOT, src), "rb") as f:
            ngc = convert(f.read())
        with open(before, "wb") as f:
            f.write(ngc)
        toml = tcp_machine_toml(machine, work)
        after = os.path.join(work, name + ".patched.ngc")
        subprocess.run(
            [polepatch_bin(), "patch", before, "-o", after, "--machine", toml],
            check=True,
            capture_output=True,
        )
        an_b = pp_json(["analyze", before, "--machine", toml, "--json"])
        an_a = pp_json(["analyze", after, "--machine", toml, "--json"])
        sim = pp_json(["simulate", before, after, "--machine", toml, "--json"])
        lc = pp_json(["simulate", before, after, "--machine", toml, "--json", "--planner", "linuxcnc"])
        near = [
            i
            for i, r in enumerate(an_b["runs"])
            if r.get("zones")
        ]
        # The blocks that move from each near-pole run's first point to its last (the
        # patch keeps every line where it is: the same windows before and after).
        windows = [(an_b["runs"][i]["lines"][0] + 1, an_b["runs"][i]["lines"][1]) for i in near]
        res_b = run_program(before, machine, False, windows)
        res_a = run_program(before, machine, True, windows)
        row = {"program": src, "machine": machine, "near_pole_runs": [an_b["runs"][i]["lines"] for i in near]}
        for tag, res, an, s_i in (("before", res_b, an_b, 0), ("after", res_a, an_a, 1)):
            if res.get("error"):
                row[tag] = {"error": res["error"]}
                continue
            runs_lcnc = res["window_times_s"]
            row[tag] = {
                "linuxcnc_cycle_time_s": res["cycle_time_s"],
                "linuxcnc_near_pole_s": sum(t for t in runs_lcnc if t is not None),
                "linuxcnc_runs_s": runs_lcnc,
                "analyze_s": sum(an["runs"][i]["time_s"] for i in near),
                "simulate_s": sum(sim[s_i]["runs"][i]["time_s"] or 0.0 for i in near),
                "model_s": sum(lc[s_i]["runs"][i]["time_s"] or 0.0 for i in near),
                "ideal_s": sum(an["runs"][i]["ideal_time_s"] for i in near),
                "peak_joint_velocity": res["peak_joint_velocity"],
                "peak_joint_acceleration": res["peak_joint_acceleration"],
                "filter": res.get("filter"),
            }
        rows.append(row)
        print(json.dumps(row)[:400], file=sys.stderr)
    if out_json:
        with open(out_json, "w") as f:
            json.dump(rows, f, indent=1)
    print_table(rows)
    print_peaks(rows)


def print_table(rows):
    print(
        "| program | machine | LinuxCNC whole program, before → after (s) | LinuxCNC near-pole runs | "
        "model (`simulate --planner linuxcnc`) | model error | analyze (Eq. 6) | simulate | L/F |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        b, a = r.get("before", {}), r.get("after", {})
        if "error" in b or "error" in a:
            print("| %s | %s | error: %s |" % (r["program"], r["machine"], b.get("error") or a.get("error")))
            continue
        if not r["near_pole_runs"]:
            print(
                "| %s | %s | %.2f → %.2f | no near-pole run | | | | | |"
                % (r["program"], r["machine"], b["linuxcnc_cycle_time_s"], a["linuxcnc_cycle_time_s"])
            )
            continue
        err = [
            100.0 * (x["model_s"] / x["linuxcnc_near_pole_s"] - 1.0) for x in (b, a) if x["linuxcnc_near_pole_s"]
        ]
        print(
            "| %s | %s | %.2f → %.2f | %.2f → %.2f | %.2f → %.2f | %s | %.2f → %.2f | %.2f → %.2f | %.2f |"
            % (
                r["program"],
                r["machine"],
                b["linuxcnc_cycle_time_s"],
                a["linuxcnc_cycle_time_s"],
                b["linuxcnc_near_pole_s"],
                a["linuxcnc_near_pole_s"],
                b["model_s"],
                a["model_s"],
                " / ".join("%+.1f %%" % e for e in err),
                b["analyze_s"],
                a["analyze_s"],
                b["simulate_s"],
                a["simulate_s"],
                b["ideal_s"],
            )
        )


def print_peaks(rows):
    """The controller's peak joint velocities and accelerations, before → after, against
    the machine's limits (LinuxCNC 2.9 plans within the world axes' limits, not the
    joints': its issue #97)."""
    print()
    print(
        "| program | machine | joint | limit V, A | peak velocity before → after | peak acceleration before → after |"
    )
    print("|---|---|---|---|---|---|")
    for r in rows:
        b, a = r.get("before", {}), r.get("after", {})
        if "error" in b or "error" in a or not r["near_pole_runs"]:
            continue
        _, m = load_machine(r["machine"])
        lim = limits(m)
        letter = m["primary"]["letter"].upper()
        for j in (0, 1, 3, 4):
            name = ("X", "Y", "Z", letter, "C")[j]
            unit = ("mm/s", "mm/s²") if j < 3 else ("°/s", "°/s²")
            print(
                "| %s | %s | %s | %.0f %s, %.0f %s | %.1f → %.1f | %.0f → %.0f |"
                % (
                    os.path.basename(r["program"]),
                    r["machine"],
                    name,
                    lim[j][0],
                    unit[0],
                    lim[j][1],
                    unit[1],
                    b["peak_joint_velocity"][j],
                    a["peak_joint_velocity"][j],
                    b["peak_joint_acceleration"][j],
                    a["peak_joint_acceleration"][j],
                )
            )


def main():
    if "--driver" in sys.argv:
        driver()
        return
    import argparse

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run one program (LinuxCNC syntax) in LinuxCNC")
    r.add_argument("program")
    r.add_argument("--machine", required=True)
    r.add_argument("--filter", action="store_true", help="open it through [FILTER] = polepatch filter")
    r.add_argument("--json")
    r.add_argument(
        "--window",
        action="append",
        default=[],
        metavar="FIRST-LAST",
        help="program lines whose time to count (window_times_s); repeatable",
    )
    c = sub.add_parser("convert", help="print a quality-suite program in LinuxCNC syntax")
    c.add_argument("program")
    t = sub.add_parser("table", help="the table of docs/validation.md")
    t.add_argument("--out")
    p = sub.add_parser("print", help="print the tables again from a `table --out` JSON")
    p.add_argument("json")
    args = ap.parse_args()
    if args.cmd == "print":
        with open(args.json) as f:
            rows = json.load(f)
        print_table(rows)
        print_peaks(rows)
        return
    if args.cmd == "convert":
        with open(args.program, "rb") as f:
            sys.stdout.buffer.write(convert(f.read()))
    elif args.cmd == "run":
        windows = [tuple(int(x) for x in w.split("-")) for w in args.window]
        res = run_program(args.program, args.machine, args.filter, windows)
        text = json.dumps(res, indent=1)
        if args.json:
            with open(args.json, "w") as f:
                f.write(text)
        else:
            print(text)
        sys.exit(1 if res.get("error") else 0)
    else:
        table(args.out)


if __name__ == "__main__":
    main()
