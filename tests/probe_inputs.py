#!/usr/bin/python3
"""Hostile-keyboard probe of the geomint experiment programs.

Usage: /usr/bin/python3 tests/probe_inputs.py [phase ...]     (from the repository, after `make build`)
Phases: options names special paths formulas signals concurrency mpi   (default: all, in that order)
Each phase writes $GEOMINT_PROBE_DIR/results_<phase>.tsv (default /tmp/geomint-probe); the phases run are also
concatenated into results.tsv. Runs one program at a time, each under `timeout -s KILL 30 timeout -s INT 20`: about 50
minutes on two cores, so it is not part of `make test`; tests/programs/probe.test.cpp holds every class of defect it found.
Environment: GEOMINT_BIN (default build/experiments), PROBE_PROGS=a,b (only these programs).
"""
import hashlib, os, re, shlex, shutil, signal, subprocess, sys, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
B = os.environ.get("GEOMINT_BIN", os.path.join(ROOT, "build", "experiments"))
PROBE = os.environ.get("GEOMINT_PROBE_DIR", "/tmp/geomint-probe")
RUNS = os.path.join(PROBE, "runs")
CANARY = os.path.join(PROBE, "PWNED")
DOCS = os.path.join(ROOT, "docs", "systems")
INNER = 20          # timeout -s INT
OUTER = 30          # timeout -s KILL

PROGRAMS = sorted(p for p in os.listdir(B) if os.access(os.path.join(B, p), os.X_OK)
                  and os.path.isfile(os.path.join(B, p)))
if os.environ.get("PROBE_PROGS"):
    PROGRAMS = [p for p in PROGRAMS if p in os.environ["PROBE_PROGS"].split(",")]

# base arguments that make an accepted run short (the probed option overrides its base entry)
BASE = {
    "anomaly_foucault": ["--runs", "2", "--T", "10", "--h", "0.1", "--alpha", "1e-3"],
    "bench_compose": ["--reps", "3", "--steps", "100"],
    "bench_ensembles": ["--reps", "3"],
    "bench_formula": ["--reps", "3", "--systems", DOCS],
    "bench_generic": ["--steps", "1000", "--reps", "3"],
    "bench_steps": ["--steps", "1000", "--reps", "3"],
    "bench_symbolic": ["--max-order", "1", "--repeat", "1", "--systems", "pendulum"],
    "convergence": ["--h-min", "0.05"],
    "ensemble": ["--runs", "10", "--T", "2"],
    "fig2_foucault": ["--T", "10", "--h", "0.1"],
    "integrate": [],
    "kepler_anchor": ["--settings", "anchor-1", "--reps", "0"],
    "long_horizon": ["--system", "oscillator", "--periods", "15", "--m", "8", "--tol", "1e-5", "--reps", "1"],
    "modified_agreement": ["--systems", "oscillator", "--orders", "0", "1"],
    "modified_cost": ["--seconds", "0.01", "--reps", "1", "--orders", "0", "1", "--systems", "pendulum"],
    "modified_equation": ["--order", "2"],
    "nonholonomic_modified": ["--systems", "knife-edge", "--orders", "1", "--radii", "3"],
    "regularized_error": ["--T", "10"],
    "stability": ["--n", "10"],
    "work_precision": ["--reps", "1", "--h-min", "0.01"],
}
# Google-benchmark programs whose every accepted run takes minutes: a shorter cap (still under 20 s)
SHORT_CAP = {"bench_compose": 6, "bench_ensembles": 6}

NON_NUMERIC = {"out", "system", "system-file", "scheme", "schemes", "path", "reference", "start", "constraint",
               "constraints", "simd", "systems", "settings", "methods", "perturb", "omega_expr", "norm", "baselines",
               "equations", "adaptive-error"}
FLAGS = {"help", "no-budget", "formulas"}
NUM_VALUES = ["0", "-1", "nan", "inf", "-inf", "1e308", "1e-320", "4e-320", "2147483648", "1e15",
              "9999999999999999999", "", "abc", "1e3x"]
NONSENSE_VALUES = {"nan", "inf", "-inf", "", "abc", "1e3x"}
TEXT_EXT = (".tsv", ".csv", ".txt", ".json", ".dat", ".md", ".m", ".tex", ".log")
NANRE = re.compile(rb"(?i)(?<![A-Za-z_])[-+]?(nan|inf|infinity)(?![A-Za-z_])")
STAGING = re.compile(r"(^\.geomint-run-|\.tmp$|\.old-|^\.geomint)")


def parse_help(prog):
    txt = subprocess.run([B + "/" + prog, "--help"], capture_output=True, text=True, timeout=10).stdout
    opts = {}
    for line in txt.splitlines():
        m = re.match(r"^\s{2}--([\w-]+)(\s+arg)?(\s+\(=([^)]*)\))?", line)
        if m:
            opts[m.group(1)] = (bool(m.group(2)), m.group(4))
    return opts


def snapshot(root):
    snap = {}
    for d, dirs, files in os.walk(root, followlinks=False):
        for n in dirs + files:
            p = os.path.join(d, n)
            rel = os.path.relpath(p, root)
            try:
                st = os.lstat(p)
            except OSError:
                continue
            if os.path.islink(p):
                snap[rel] = ("l", os.readlink(p))
            elif os.path.isdir(p):
                snap[rel] = ("d", "")
            else:
                h = hashlib.sha1()
                try:
                    with open(p, "rb") as f:
                        h.update(f.read(1 << 26))
                except OSError:
                    pass
                snap[rel] = ("f", st.st_size, h.hexdigest())
    return snap


def nan_files(root):
    bad = []
    for d, dirs, files in os.walk(root):
        for n in files:
            if n.endswith(TEXT_EXT):
                p = os.path.join(d, n)
                try:
                    with open(p, "rb") as f:
                        data = f.read(1 << 24)
                except OSError:
                    continue
                m = NANRE.search(data)
                if m:
                    ln = data[:m.start()].count(b"\n") + 1
                    bad.append("%s:%d:%s" % (os.path.relpath(p, root), ln, m.group(0).decode()))
    return bad


class Log:
    def __init__(self, phase):
        self.path = os.path.join(PROBE, "results_%s.tsv" % phase)
        self.f = open(self.path, "w")
        self.f.write("id\tprogram\tcommand\texit\tseconds\tstderr_lines\tstderr_first_line\tclass\tnote\n")
        self.counts = {}

    def add(self, rid, prog, cmd, rc, secs, nlines, first, cls, note):
        clean = lambda s: s.replace("\t", " ").replace("\n", "\\n")[:400]
        self.f.write("%s\t%s\t%s\t%s\t%.2f\t%d\t%s\t%s\t%s\n" % (rid, prog, clean(cmd), rc, secs, nlines,
                                                             clean(first), cls, clean(note)))
        self.f.flush()
        self.counts[cls] = self.counts.get(cls, 0) + 1


COUNTER = [0]


def new_rundir(phase):
    COUNTER[0] += 1
    rid = "%s-%05d" % (phase, COUNTER[0])
    r = os.path.join(RUNS, rid)
    shutil.rmtree(r, ignore_errors=True)
    os.makedirs(r)
    pre = os.path.join(r, "pre")
    os.makedirs(os.path.join(pre, "sub"))
    with open(os.path.join(pre, "keep.txt"), "w") as f:
        f.write("previous output\n")
    with open(os.path.join(pre, "sub", "old.tsv"), "w") as f:
        f.write("# old\n1\t2\n")
    return rid, r


def run_one(log, phase, prog, args, nonsense=False, out_mode="auto", review=False, cap=None, extra_note="",
            env=None):
    """Run prog with args (+ --out) and classify. out_mode: 'new', 'pre', 'auto' (alternate) or 'given'."""
    rid, r = new_rundir(phase)
    if out_mode == "auto":
        out_mode = "pre" if COUNTER[0] % 2 else "new"
    args = list(args)
    if out_mode in ("new", "pre"):
        args += ["--out", os.path.join(r, out_mode)]
    cap = cap or SHORT_CAP.get(prog, INNER)
    cmd = ["timeout", "-s", "KILL", str(OUTER), "timeout", "-s", "INT", str(cap), os.path.join(B, prog)] + args
    before = snapshot(r)
    canary_before = os.path.exists(CANARY)
    t0 = time.time()
    try:
        p = subprocess.run(cmd, cwd=r, capture_output=True, timeout=OUTER + 10, env=env)
        rc, so, se = p.returncode, p.stdout, p.stderr
    except subprocess.TimeoutExpired:
        rc, so, se = -999, b"", b""
    secs = time.time() - t0
    after = snapshot(r)
    set_text = se.decode("utf-8", "replace")
    lines = [l for l in set_text.split("\n") if l != ""]
    raw_lines = set_text.count("\n") + (0 if set_text.endswith("\n") or not set_text else 1)
    first = lines[0] if lines else ""
    notes = []
    defect = []
    # leftovers anywhere under the run dir (staging, tmp, old-)
    left = [k for k in after if STAGING.search(os.path.basename(k))]
    if left:
        defect.append("leftover " + ",".join(sorted(left))[:200])
    if os.path.exists(CANARY) and not canary_before:
        defect.append("SHELL INJECTION: canary created")
    shown = prog + " " + " ".join(shlex.quote(a) for a in args)
    outpath = os.path.join(r, out_mode) if out_mode in ("new", "pre") else None
    if rc in (124, 137) or rc == -999 or rc < 0 or rc > 128:
        if rc == 124 and "interrupted by signal" in set_text:
            cls = "L"  # accepted, ran past the cap, stopped cleanly by the SIGINT of timeout
            notes.append("accepted, ran > %ds" % cap)
            if out_mode == "pre":
                pre_before = {k: v for k, v in before.items() if k.startswith("pre")}
                pre_after = {k: v for k, v in after.items() if k.startswith("pre")}
                if pre_before != pre_after:
                    defect.append("previous outputs changed after SIGINT")
            if out_mode == "new" and os.path.exists(outpath):
                notes.append("new out exists after interrupt")
        elif rc == 124:
            defect.append("timeout (no interrupt message) " + repr(first[:100]))
        elif rc == 137 or rc == -999:
            defect.append("HANG: killed by outer SIGKILL")
        else:
            defect.append("CRASH: signal/exit %d" % rc)
        cls = "L" if not defect else "c"
    elif rc != 0:
        # refusal
        if raw_lines != 1:
            defect.append("refusal with %d stderr lines" % raw_lines)
        new_entries = sorted(set(after) - set(before))
        changed = sorted(k for k in before if k in after and before[k] != after[k])
        gone = sorted(set(before) - set(after))
        if new_entries:
            defect.append("refusal created " + ",".join(new_entries)[:200])
        if changed or gone:
            defect.append("refusal changed/removed " + ",".join(changed + gone)[:200])
        if so.strip():
            notes.append("stdout on refusal: " + so.decode("utf-8", "replace").strip().split("\n")[0][:80])
        cls = "c" if defect else "a"
    else:
        if nonsense:
            defect.append("exit 0 on nonsense input")
        if outpath and os.path.isdir(outpath):
            bad = nan_files(outpath)
            if bad:
                defect.append("NaN/inf in output: " + "; ".join(bad[:3]))
            if out_mode == "pre" and not os.path.exists(os.path.join(outpath, "keep.txt")):
                notes.append("user file keep.txt in --out removed")
        elif outpath:
            notes.append("exit 0 but no --out folder")
        cls = "c" if defect else "b"
        if review and not defect:
            notes.append("REVIEW: accepted")
    note = "; ".join(defect + notes + ([extra_note] if extra_note else []))
    log.add(rid, prog, shown, rc, secs, raw_lines, first, cls, note)
    if cls != "c":
        shutil.rmtree(r, ignore_errors=True)
    else:
        # keep the evidence, drop big plots
        for d, _, files in os.walk(r):
            for n in files:
                if n.endswith((".png", ".pdf")):
                    try:
                        os.remove(os.path.join(d, n))
                    except OSError:
                        pass
    print("%-4s %-24s rc=%-4s %5.1fs %s | %s" % (cls, prog, rc, secs, first[:90], note[:120]), flush=True)
    return cls, rc, set_text


def with_base(prog, opt, vals):
    base = list(BASE.get(prog, []))
    # remove the probed option (and its values) from the base
    out, i = [], 0
    while i < len(base):
        if base[i] == "--" + opt:
            i += 1
            while i < len(base) and not base[i].startswith("--"):
                i += 1
            continue
        out.append(base[i])
        i += 1
    return out + ["--" + opt] + vals


def base_without(prog, opt):
    return with_base(prog, opt, [])[:-1]


# ---------------------------------------------------------------------------------------------- phases
def phase_options(log):
    for prog in PROGRAMS:
        opts = parse_help(prog)
        for opt, (has_arg, default) in opts.items():
            if opt in FLAGS or opt in NON_NUMERIC or not has_arg:
                continue
            if default and not re.match(r"^[-+0-9.eE ]+$", default) and opt != "omega":
                continue
            for v in NUM_VALUES:
                run_one(log, "options", prog, with_base(prog, opt, [v]), nonsense=v in NONSENSE_VALUES,
                        review=v not in NONSENSE_VALUES)
            # repeated option (scalar: should be refused or documented)
            d = (default or "1").split()[0]
            if opt == "omega":
                d = "1"
            run_one(log, "options", prog, with_base(prog, opt, [d]) + ["--" + opt, d], review=True,
                    extra_note="repeated option")
        # generic command-line garbage
        base = BASE.get(prog, [])
        for extra in (["--bogus", "1"], ["stray"], ["--", "x"], ["-Z"], ["--no-budget=yes"], ["--out"],
                      ["--help=x"], ["--system", "nosuchsystem"] if "system" in opts else ["--system", "x"]):
            run_one(log, "options", prog, base + extra, nonsense=True, out_mode="auto" if extra != ["--out"] else "given")


def name_lists(prog, opts):
    cases = []
    if "system" in opts:
        for v in ["", "abc", "PENDULUM", " pendulum", "pendulum;touch " + CANARY, "$(touch %s)" % CANARY]:
            cases.append((["--system", v], True))
        cases.append((["--system", "pendulum", "--system", "oscillator"], False))
        cases.append((["--system", "pendulum", "--system-file", DOCS + "/pendulum.geomint"], True))
    if "scheme" in opts:
        for v in ["", "abc", "la;touch " + CANARY, "yoshida4:", ":la", "yoshida4:la", "yoshida4:yoshida4:la-midpoint",
                  "nosuch:la-midpoint", "la "]:
            cases.append((["--scheme", v], True))
        cases.append((["--scheme", "la", "--scheme", "contact"], False))
        cases.append((["--scheme", "kahanli8:la-midpoint"], False))
    for lst in ("schemes", "systems", "settings", "methods", "constraints"):
        if lst in opts and not (prog == "bench_formula" and lst == "systems"):
            default = (opts[lst][1] or "").split()
            good = default[0] if default else {"schemes": "la", "settings": "anchor-1", "methods": "odeint-rk4",
                                               "systems": "pendulum", "constraints": "paper"}[lst]
            for vals, nons in ([[""], True], [["abc"], True], [[good, good], False], [[good, "abc"], True],
                               [["abc", good], True], [[good + ",abc"], True], [[","], True],
                               [["$(touch %s)" % CANARY], True]):
                cases.append((["--" + lst] + vals, nons))
            cases.append((["--" + lst], True))  # no value
    for single in ("path", "reference", "start", "constraint", "simd"):
        if single in opts:
            for v in ["", "abc", "FAST", "fast generic"]:
                cases.append((["--" + single] + v.split(" ") if v else ["--" + single, ""], True))
    if "simd" in opts:
        for v in ["avx512", "avx2", "sse2", "scalar"]:
            cases.append((["--simd", v], False))
    if "perturb" in opts:
        for v, nons in [("", True), ("abc", True), ("theta0=", True), ("theta0=nan", True), ("nosuch=1e-3", True),
                        ("theta0=-1", False), ("theta0=1e308", False), ("T=1", False), ("theta0=1e-3 theta0=1e-3", False),
                        ("=1", True), ("theta0==1", True)]:
            cases.append((["--perturb"] + (v.split(" ") if v else [""]), nons))
    if prog == "long_horizon":  # the forced oscillator's study: --omega is an expression
        forced = ["--system", "forced-oscillator", "--periods", "10", "--m", "8", "--tol", "1e-5", "--reps", "1"]
        for v, nons in [("pi/0", True), ("pi*", True), ("2*pi/3", False), ("pi/3;touch " + CANARY, True),
                        ("$(touch %s)" % CANARY, True), ("sqrt(-1)", True), ("1/0", True), ("pi/3 pi/3", True),
                        ("PI/3", True), ("`touch %s`" % CANARY, True)]:
            cases.append((forced + ["--omega"] + v.split(" "), nons))
    if prog == "modified_equation":
        for v, nons in [("0.5 0.5", True), ("", True), ("nan", True)]:
            cases.append((["--q"] + (v.split(" ") if v else [""]), nons))
    return cases


def phase_names(log):
    for prog in PROGRAMS:
        opts = parse_help(prog)
        for extra, nons in name_lists(prog, opts):
            key = extra[0][2:]
            run_one(log, "names", prog, with_base(prog, key, []) [:-1] + extra, nonsense=nons, review=not nons)


SPECIAL = [
    ("integrate", ["--T", "1e10", "--h", "0.1"]),
    ("regularized_error", ["--T", "1e8"]),
    ("regularized_error", ["--T", "1e10"]),
    ("modified_cost", ["--seconds", "10", "--reps", "100"]),
    ("convergence", ["--system", "foucault", "--T", "1e7"]),
    ("modified_agreement", ["--T", "1e7"]),
    ("nonholonomic_modified", ["--T", "1e8"]),
    ("anomaly_foucault", ["--runs", "1000000", "--no-budget"]),
    ("regularized_error", ["--system", "oscillator", "--reference", "leapfrog", "--T", "4e6"]),
    ("bench_steps", ["--steps", "1e15"]),
    ("bench_steps", ["--reps", "2147483647"]),
    ("stability", ["--alpha-max", "1e308"]),
    ("stability", ["--h-max", "1e308"]),
    ("stability", ["--alpha-min", "1e-320"]),
    ("work_precision", ["--h-max", "nan"]),
    ("work_precision", ["--T", "1e308"]),
    ("fig2_foucault", ["--sample-dt", "1e300"]),
    ("regularized_error", ["--system", "oscillator", "--reference", "leapfrog", "--T", "4e-320", "--h", "4e-320"]),
    ("ensemble", ["--runs", "10000000"]),
    # more of the same kind
    ("integrate", ["--T", "1e10", "--h", "0.1", "--no-budget"]),
    ("integrate", ["--T", "1e7", "--h", "0.1", "--every", "1"]),
    ("integrate", ["--T", "1e7", "--h", "0.1", "--no-budget"]),
    ("integrate", ["--T", "20", "--h", "0.3"]),
    ("integrate", ["--T", "20", "--h", "20"]),
    ("integrate", ["--T", "20", "--h", "40"]),
    ("integrate", ["--h", "1e-300"]),
    ("integrate", ["--h", "1e-300", "--no-budget"]),
    ("integrate", ["--every", "0"]),
    ("integrate", ["--every", "1e15"]),
    ("integrate", ["--system", "kepler", "--scheme", "kahanli8:la-midpoint", "--T", "1e6", "--h", "0.01"]),
    ("integrate", ["--system", "knife-edge", "--m", "0"]),
    ("integrate", ["--system", "knife-edge", "--I", "0"]),
    ("integrate", ["--system", "pendulum", "--q0", "1e308"]),
    ("integrate", ["--system", "pendulum", "--alpha", "1e308"]),
    ("integrate", ["--system", "oscillator", "--alpha", "-1e3", "--T", "50"]),
    ("integrate", ["--system", "duffing", "--q0", "1e200"]),
    ("integrate", ["--system", "kepler", "--q0", "0"]),
    ("ensemble", ["--runs", "2000000000", "--no-budget"]),
    ("ensemble", ["--runs", "100000", "--T", "1e5", "--no-budget"]),
    ("ensemble", ["--threads", "100000"]),
    ("ensemble", ["--threads", "0"]),
    ("anomaly_foucault", ["--threads", "4096"]),
    ("anomaly_foucault", ["--runs", "1000000"]),
    ("stability", ["--n", "100000"]),
    ("stability", ["--n", "100000", "--no-budget"]),
    ("stability", ["--h-min", "10", "--h-max", "0.01"]),
    ("stability", ["--h-min", "1", "--h-max", "1"]),
    ("convergence", ["--h-min", "1e-300"]),
    ("convergence", ["--h-min", "1e-300", "--no-budget"]),
    ("convergence", ["--h-max", "0.001", "--h-min", "0.1"]),
    ("convergence", ["--tol", "1e-30"]),
    ("convergence", ["--tol", "0"]),
    ("modified_equation", ["--order", "6", "--formulas", "--budget", "1e9"]),
    ("modified_equation", ["--order", "6", "--formulas", "--budget", "0"]),
    ("bench_symbolic", ["--max-order", "6", "--budget", "1e308"]),
    ("fig2_foucault", ["--sample-dt", "1e-300"]),
    ("fig2_foucault", ["--T", "1e9", "--no-budget"]),
    ("long_horizon", ["--periods", "1e12"]),
    ("long_horizon", ["--system", "forced-oscillator", "--periods", "1e12", "--no-budget"]),
    ("long_horizon", ["--system", "foucault", "--T", "1e12", "--no-budget"]),
    ("long_horizon", ["--system", "pendulum", "--horizons", "1e6", "--no-budget"]),
    ("kepler_anchor", ["--tau", "1e-12"]),
    ("kepler_anchor", ["--T", "1e12", "--no-budget"]),
    ("work_precision", ["--h-min", "1e-300", "--no-budget"]),
    ("modified_cost", ["--seconds", "1e308"]),
    ("modified_cost", ["--seconds", "1e308", "--no-budget"]),
    ("bench_steps", ["--steps", "1e15", "--no-budget"]),
]


def phase_special(log):
    for prog, args in SPECIAL:
        run_one(log, "special", prog, args, review=True)


def phase_paths(log):
    prog = "integrate"
    longp = os.path.join(RUNS, "L" * 100)
    # outputs: each case is (args-builder taking the run dir, nonsense?)
    afile = os.path.join(PROBE, "afile")
    with open(afile, "w") as f:
        f.write("a file\n")
    sd = os.path.join(PROBE, "symtarget")
    os.makedirs(sd, exist_ok=True)
    for n in ("lnk", "dangling", "loop1", "loop2"):
        try:
            os.remove(os.path.join(PROBE, n))
        except OSError:
            pass
    os.symlink(sd, os.path.join(PROBE, "lnk"))
    os.symlink(os.path.join(PROBE, "nowhere"), os.path.join(PROBE, "dangling"))
    os.symlink(os.path.join(PROBE, "loop2"), os.path.join(PROBE, "loop1"))
    os.symlink(os.path.join(PROBE, "loop1"), os.path.join(PROBE, "loop2"))

    def long_path(total):
        # build a path of ~total characters under RUNS out of 200-char components
        base = os.path.join(RUNS, "longpath")
        p = base
        while len(p) + 201 < total:
            p = os.path.join(p, "d" * 200)
        rest = total - len(p) - 1
        return os.path.join(p, "e" * max(1, min(rest, 250)))

    cases = [
        ("o;touch " + CANARY, False), ("o$(touch %s)" % CANARY, False), ("o`touch %s`" % CANARY, False),
        ("o'\"x", False), ("o\nx", False), ("o x y", False), ("o|cat", False), ("o&&touch " + CANARY, False),
        ("", True), ("-x", True), ("/proc/geomint-probe", True), ("/proc/self/geomint/x", True), ("/sys/geomint", True),
        ("/dev/null", True), (afile, True), (afile + "/sub", True), (os.path.join(PROBE, "lnk"), False),
        (os.path.join(PROBE, "lnk", "inner"), False), (os.path.join(PROBE, "dangling"), None),
        (os.path.join(PROBE, "loop1"), True), ("x" * 256, True), ("x" * 255, False),
        (long_path(3990), False), (long_path(4090), None), (long_path(4100), True), (long_path(5000), True),
        ("~", False), ("o/", False), ("o//p/./q/../r", False),
    ]
    for path, nons in cases:
        # relative paths resolve inside the run dir (cwd)
        cls, rc, se = run_one(log, "paths", prog, ["--T", "2", "--out", path], nonsense=bool(nons),
                              review=nons is None, out_mode="given")
    # symlinked out dir: target must hold the set, link still a link
    shutil.rmtree(os.path.join(PROBE, "longpath"), ignore_errors=True)
    shutil.rmtree(os.path.join(RUNS, "longpath"), ignore_errors=True)
    print("symtarget after:", os.listdir(sd), "lnk is link:", os.path.islink(os.path.join(PROBE, "lnk")))
    # read-only filesystem location for --system-file & non-readable file (root can read anything)
    for sf in ["/nonexistent.geomint", PROBE, "/dev/null", "/dev/zero", afile, "/proc/self/mem",
               "f;touch " + CANARY, "$(touch %s).geomint" % CANARY]:
        run_one(log, "paths", prog, ["--system-file", sf], nonsense=True)


GOOD = """[system]
name = NAME
coordinates = 1
[parameters]
alpha = 0.1
q0 = 1
p0 = 0
T = 20
[dynamics]
L = v1*v1/2 - (1 - cos(q1))
herglotz = L - alpha*z
F1 = -alpha*v1
[initial]
q1 = q0
v1 = p0
"""


def phase_formulas(log):
    d = os.path.join(PROBE, "formulas")
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    g = GOOD.replace("NAME", "probe")
    variants = {
        "good": (g, False),
        "syntax": (g.replace("L = v1*v1/2 - (1 - cos(q1))", "L = v1*v1/2 - (1 - cos(q1)"), True),
        "syntax2": (g.replace("L = v1*v1/2", "L = v1**/2"), True),
        "unknown_symbol": (g.replace("cos(q1)", "cosh(q1)"), True),
        "unknown_name": (g.replace("cos(q1)", "cos(qq1)"), True),
        "coord_beyond": (g.replace("cos(q1)", "cos(q2)"), True),
        "div0_param": (g.replace("alpha = 0.1", "alpha = 1/0"), True),
        "div0_L": (g.replace("L = v1*v1/2 - (1 - cos(q1))", "L = v1*v1/2 - 1/(q1-1)"), True),
        "div0_force": (g.replace("F1 = -alpha*v1", "F1 = -alpha*v1/0"), True),
        "log_neg": (g.replace("q0 = 1", "q0 = log(-1)"), True),
        "sqrt_neg_dyn": (g.replace("L = v1*v1/2 - (1 - cos(q1))", "L = v1*v1/2 - sqrt(q1-2)"), True),
        "shell_subst": (g.replace("L = v1*v1/2 - (1 - cos(q1))", "L = $(touch %s)" % CANARY), True),
        "shell_backtick": (g.replace("L = v1*v1/2 - (1 - cos(q1))", "L = `touch %s`" % CANARY), True),
        "shell_semicolon": (g.replace("F1 = -alpha*v1", "F1 = -alpha*v1; touch " + CANARY), True),
        "name_meta": (GOOD.replace("NAME", "x;touch " + CANARY), True),
        "name_slash": (GOOD.replace("NAME", "../../escape"), True),
        "name_long": (GOOD.replace("NAME", "n" * 300), True),
        "name_empty": (GOOD.replace("name = NAME\n", ""), True),
        "missing_T": (g.replace("T = 20\n", ""), True),
        "T_huge": (g.replace("T = 20", "T = 1e308"), True),
        "T_nan": (g.replace("T = 20", "T = 0/0"), True),
        "T_neg": (g.replace("T = 20", "T = -5"), True),
        "coords0": (g.replace("coordinates = 1", "coordinates = 0"), True),
        "coords_huge": (g.replace("coordinates = 1", "coordinates = 99999999999"), True),
        "coords_neg": (g.replace("coordinates = 1", "coordinates = -1"), True),
        "singular_hessian": (g.replace("L = v1*v1/2 - (1 - cos(q1))", "L = v1 - cos(q1)"), True),
        "L_depends_z": (g.replace("L = v1*v1/2 - (1 - cos(q1))", "L = v1*v1/2 - z"), True),
        "empty": ("", True),
        "binary": ("\x00\x01\x02\xff" * 100, True),
        "dup_key": (g.replace("alpha = 0.1", "alpha = 0.1\nalpha = 0.2"), True),
        "dup_section": (g + "[dynamics]\nL = v1*v1\n", True),
        "deep_nesting": (g.replace("L = v1*v1/2 - (1 - cos(q1))", "L = v1*v1/2 - " + "(" * 100000 + "q1" + ")" * 100000), True),
        "huge_power": (g.replace("L = v1*v1/2 - (1 - cos(q1))", "L = v1*v1/2 - q1^1e308"), True),
        "right_assoc_tower": (g.replace("L = v1*v1/2 - (1 - cos(q1))", "L = v1*v1/2 - " + "^".join(["q1"] * 5000)), True),
        "long_line": (g.replace("L = v1*v1/2 - (1 - cos(q1))", "L = v1*v1/2 - " + "+".join(["cos(q1)"] * 200000)), None),
        "unknown_section": (g + "[weird]\nx = 1\n", True),
        "definition_cycle": (g.replace("[dynamics]", "[definitions]\na = b\nb = a\n[dynamics]"), True),
        "crlf": (g.replace("\n", "\r\n"), None),
        "utf8_name": (g.replace("alpha", "αlpha"), True),
    }
    for name, (text, nons) in variants.items():
        path = os.path.join(d, name + ".geomint")
        with open(path, "w", encoding="utf-8", errors="surrogateescape") as f:
            f.write(text)
        run_one(log, "formulas", "integrate", ["--system-file", path, "--T", "2"], nonsense=bool(nons),
                review=nons is None, extra_note="formula:" + name)
    # the same malformed files in other programs that take --system-file
    for prog in ("convergence", "ensemble", "modified_equation", "regularized_error", "stability",
                 "work_precision"):
        for name in ("syntax", "div0_L", "shell_subst", "name_slash", "T_huge", "good"):
            path = os.path.join(d, name + ".geomint")
            run_one(log, "formulas", prog, base_without(prog, "T") + ["--system-file", path],
                    nonsense=name != "good", review=name == "good", extra_note="formula:" + name)


def hash_tree(p):
    return snapshot(p) if os.path.isdir(p) else None


def phase_signals(log):
    sigs = ["INT", "TERM", "HUP", "QUIT", "XFSZ", "USR1", "USR2", "ALRM"]
    jobs = [("integrate", ["--path", "generic", "--T", "1e6", "--h", "0.01", "--every", "1000"]),
            ("stability", ["--n", "400"]),
            ("ensemble", ["--runs", "20000", "--T", "200"])]
    for prog, args in jobs:
        # a previous output set into pre
        for s in sigs:
            rid, r = new_rundir("signals")
            out = os.path.join(r, "pre")
            before = snapshot(r)
            cmd = ["timeout", "-s", "KILL", str(OUTER), "timeout", "-s", "INT", str(INNER), os.path.join(B, prog)] \
                + args + ["--out", out]
            t0 = time.time()
            p = subprocess.Popen(cmd, cwd=r, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
            time.sleep(1.5)
            # signal the program itself (child of the inner timeout)
            pid = None
            try:
                kids = subprocess.run(["pgrep", "-P", str(p.pid)], capture_output=True, text=True).stdout.split()
                kids2 = subprocess.run(["pgrep", "-P", kids[0]], capture_output=True, text=True).stdout.split() if kids else []
                pid = int(kids2[0]) if kids2 else None
            except Exception:
                pid = None
            if pid:
                os.kill(pid, getattr(signal, "SIG" + s))
            so, se = p.communicate(timeout=OUTER + 10)
            rc = p.returncode
            secs = time.time() - t0
            after = snapshot(r)
            text = se.decode("utf-8", "replace")
            nl = text.count("\n") + (0 if text.endswith("\n") or not text else 1)
            lines = [l for l in text.split("\n") if l]
            defect = []
            if pid is None:
                defect.append("finished before the signal (no pid)")
            if rc == 0:
                defect.append("exit 0 after signal")
            if rc in (124, 137):
                defect.append("did not stop on signal (timeout)")
            sig_lines = [l for l in lines if "signal" in l or "interrupt" in l]
            if len(sig_lines) != 1:
                defect.append("%d signal message lines" % len(sig_lines))
            if before != after:
                ch = sorted(set(after) ^ set(before)) + sorted(k for k in before if k in after and before[k] != after[k])
                defect.append("folder changed: " + ",".join(ch)[:200])
            cls = "c" if defect and pid else ("a" if pid else "x")
            log.add(rid, prog, "kill -%s %s %s --out pre" % (s, prog, " ".join(args)), rc, secs, nl,
                    (sig_lines or [""])[-1], "sig-" + cls, "; ".join(defect) + " | stderr lines=%d" % nl)
            print("sig %s %s rc=%s lines=%d %s %s" % (prog, s, rc, nl, (sig_lines or [""])[-1][:90], defect), flush=True)
            if cls != "c":
                shutil.rmtree(r, ignore_errors=True)


def phase_concurrency(log):
    prog = "integrate"
    G = ["--path", "generic", "--h", "0.01", "--every", "100"]
    pairs = [(G + ["--T", "3e5"], ["--T", "20", "--h", "0.1"]),
             (["--T", "20", "--h", "0.1"], G + ["--T", "3e5"]),
             (G + ["--T", "3e5"], G + ["--T", "2e5"]),
             (G + ["--T", "3e5"], G + ["--system", "oscillator", "--T", "3e5"])]
    for delay in (0.0, 0.3, 1.5):
        for a1, a2 in pairs:
            rid, r = new_rundir("concurrency")
            out = os.path.join(r, "same")
            mk = lambda a: ["timeout", "-s", "KILL", str(OUTER), "timeout", "-s", "INT", str(INNER),
                            os.path.join(B, prog)] + a + ["--out", out]
            t0 = time.time()
            p1 = subprocess.Popen(mk(a1), cwd=r, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
            time.sleep(delay)
            p2 = subprocess.Popen(mk(a2), cwd=r, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
            o1, e1 = p1.communicate(timeout=OUTER + 10)
            o2, e2 = p2.communicate(timeout=OUTER + 10)
            secs = time.time() - t0
            files = sorted(os.listdir(out)) if os.path.isdir(out) else []
            allr = snapshot(r)
            left = [k for k in allr if STAGING.search(os.path.basename(k))]
            defect = []
            # consistency: every tsv header must agree with the file set; expect exactly the set of one run
            tsvs = [f for f in files if f.endswith(".tsv")]
            systems = set()
            for t in tsvs:
                with open(os.path.join(out, t), errors="replace") as f:
                    head = f.read(2000)
                m = re.search(r"# system: (\S+)", head)
                mT = re.search(r"# T: (\S+)", head)
                systems.add((m.group(1) if m else "?", mT.group(1) if mT else "?"))
            stems = set(f.rsplit(".", 1)[0] for f in files)
            if len(stems) > 1:
                defect.append("mixed set: " + ",".join(files))
            if len(systems) > 1:
                defect.append("mixed headers %s" % systems)
            # plot must belong to the same run as the table: compare mtimes roughly
            if left:
                defect.append("leftover " + ",".join(left))
            e1t, e2t = e1.decode(errors="replace"), e2.decode(errors="replace")
            for rc, et in ((p1.returncode, e1t), (p2.returncode, e2t)):
                if rc != 0 and et.count("\n") != 1:
                    defect.append("refusal with %d lines" % et.count("\n"))
                if rc in (124, 137) or rc < 0 or rc > 128:
                    defect.append("rc %d" % rc)
            cls = "conc-" + ("c" if defect else "ok")
            note = "rc1=%d rc2=%d files=%s hdr=%s e1=%r e2=%r %s" % (p1.returncode, p2.returncode, files, systems,
                                                                    e1t.strip()[:300], e2t.strip()[:300], "; ".join(defect))
            log.add(rid, prog, "delay=%.1f A=%s B=%s" % (delay, " ".join(a1), " ".join(a2)), "%d/%d" % (p1.returncode, p2.returncode),
                    secs, e2t.count("\n"), e2t.strip().split("\n")[0] if e2t.strip() else "", cls, note)
            print(cls, note[:300], flush=True)
            if not defect:
                shutil.rmtree(r, ignore_errors=True)


def phase_mpi(log):
    if not shutil.which("mpiexec"):
        return
    mpi = ["mpiexec", "--allow-run-as-root", "--oversubscribe", "-n", "2"]
    cases = [("integrate", ["--h", "abc"], True), ("integrate", ["--bogus"], True), ("ensemble", ["--runs", "-1"], True),
             ("ensemble", ["--system", "nosuch"], True), ("ensemble", ["--runs", "1000000000"], True),
             ("ensemble", ["--runs", "200", "--T", "2"], False), ("integrate", ["--T", "2"], False),
             ("anomaly_foucault", ["--runs", "2", "--T", "10", "--h", "0.1", "--alpha", "1e-3"], False),
             ("ensemble", ["--runs", "200", "--T", "2", "--threads", "0"], True),
             ("convergence", ["--h-min", "abc"], True)]
    for prog, args, nons in cases:
        rid, r = new_rundir("mpi")
        out = os.path.join(r, "new")
        cmd = ["timeout", "-s", "KILL", str(OUTER), "timeout", "-s", "INT", str(INNER)] + mpi + \
            [os.path.join(B, prog)] + args + ["--out", out]
        t0 = time.time()
        p = subprocess.run(cmd, cwd=r, capture_output=True)
        secs = time.time() - t0
        se = p.stderr.decode(errors="replace")
        lines = [l for l in se.split("\n") if l.strip()]
        prog_lines = [l for l in lines if l.startswith(prog + ":")]
        after = snapshot(r)
        defect = []
        if nons:
            if p.returncode == 0:
                defect.append("exit 0 on bad input")
            if len(prog_lines) != 1:
                defect.append("%d program error lines (%d stderr lines)" % (len(prog_lines), len(lines)))
            if os.path.exists(out):
                defect.append("out created on refusal")
        else:
            if p.returncode != 0:
                defect.append("failed under MPI")
            files = sorted(os.listdir(out)) if os.path.isdir(out) else []
            if not files:
                defect.append("no output")
        left = [k for k in after if STAGING.search(os.path.basename(k))]
        if left:
            defect.append("leftover " + ",".join(left))
        cls = "mpi-" + ("c" if defect else "ok")
        note = "; ".join(defect) + " | stderr: " + " // ".join(lines[:4])
        log.add(rid, prog, "mpiexec -n 2 %s %s" % (prog, " ".join(shlex.quote(a) for a in args)), p.returncode, secs,
                len(lines), lines[0] if lines else "", cls, note)
        print(cls, prog, args, p.returncode, note[:300], flush=True)
        if not defect:
            shutil.rmtree(r, ignore_errors=True)


PHASES = {"options": phase_options, "names": phase_names, "special": phase_special, "paths": phase_paths,
          "formulas": phase_formulas, "signals": phase_signals, "concurrency": phase_concurrency, "mpi": phase_mpi}

if __name__ == "__main__":
    chosen = sys.argv[1:] or list(PHASES)
    os.makedirs(RUNS, exist_ok=True)
    if os.path.exists(CANARY):
        os.remove(CANARY)
    for ph in chosen:
        COUNTER[0] = 0
        log = Log(ph)
        t0 = time.time()
        PHASES[ph](log)
        print("== phase %s: %s in %.0fs" % (ph, log.counts, time.time() - t0), flush=True)
    # results.tsv: every phase's log in one table
    with open(os.path.join(PROBE, "results.tsv"), "w") as out:
        for i, ph in enumerate(chosen):
            with open(os.path.join(PROBE, "results_%s.tsv" % ph)) as f:
                lines = f.readlines()
                out.writelines(lines if i == 0 else lines[1:])  # one header
    print("canary exists:", os.path.exists(CANARY))
