#!/usr/bin/env python3
"""Mutation campaign: every input kind roamlab reads, mutated, run through the command that reads it.

Seeds: a short synthetic recording and a small bag as ROS 1, MCAP and rosbag2 SQLite
(build/tests/support/make_mutation_seeds), the repository's scenario and estimator YAML, a regression suite of one
calibration case on the synthetic recording, an OptiOdom run with its metadata and a CSV log with its import mapping
(written here).
Each mutant is one operator applied to one seed file; the command runs with a timeout and its outcome is classified:

  clean      exit 2, one line on stderr (warnings aside) that names the mutated file
  unclean    refused, but with exit 1 for clearly bad data, several lines, or a line that does not name the file
  failure    exit 1 with at most one line after a neutral mutation: a run-time failure (the solver diverged, a
             regression check that a changed bound fails), not bad input
  accepted   exit 0 after a neutral mutation (a change the data may legitimately carry)
  silent     exit 0 after a mutation that makes the data clearly bad (duplicate key, truncated row, NaN, absurd
             magnitude, undeclared name, ...): a silent acceptance
  crash      killed by a signal, exit code above 2, or an exception or CHECK text on stderr
  hang       still running at the timeout

Usage: tools/mutate.py --roamlab build/apps/roamlab --seeds-tool build/tests/support/make_mutation_seeds
                       [--per-kind 55] [--seed 1] [--timeout 60] [--work DIR] [--markdown FILE] [--list-failures]
Exit code 1 when any mutant crashed, hung or was silently accepted.
"""
import argparse
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CRASH_TEXT = ("terminate called", "CHECK failed", "Assertion", "AddressSanitizer", "runtime error:", "Aborted")

OPTIODOM_METADATA = "type,tricyc,\nngear,1,\nencRes,1600,\nLi,0.15,\nDi,0.065,\nThi,-0.02,\nN,2,\n"
CSV_LOG = "time_s,gx,gy,gz,ax,ay,az,lat,lon,alt\n" + "".join(
    "%.1f,%.1f,0.0,-1.0,0.0,%.1f,1.0,%.5f,9.0,120.0\n" % (0.1 * k, 1.0 + k, 0.1 * k, 45.0 + 1e-5 * (k // 3))
    for k in range(20))
CSV_MAP = ("time: {column: time_s, unit: s}\n"
           "streams:\n"
           "  imu: {type: imu, columns: [gx, gy, gz, ax, ay, az], units: [deg/s, deg/s, deg/s, g, g, g]}\n"
           "  gps: {type: gps, columns: [lat, lon, alt], collapse: by_change}\n")


def optiodom_run():
    rows = []
    for k in range(40):
        rows.append("%.2f,%.4f,%.4f,%.4f,%d,%.3f" % (0.05 * k, 0.001 * k, 0.0002 * k, 0.01 * k, 40, 0.1))
    return "\n".join(rows) + "\n"


# ---- operators: each takes (text, rng) and returns the mutated text or None when it does not apply ----

NUMBER = re.compile(r"(?<![\w.])-?\d+(\.\d+)?([eE][-+]?\d+)?(?![\w.])")


def numbers_outside_comments(text):
    """The numbers of `text` that are not inside a '#' comment (a YAML comment; CSV text has none)."""
    out = []
    for m in NUMBER.finditer(text):
        line_start = text.rfind("\n", 0, m.start()) + 1
        if "#" not in text[line_start:m.start()]:
            out.append(m)
    return out


def replace_number(value):
    def op(text, rng):
        matches = numbers_outside_comments(text)
        if not matches:
            return None
        m = rng.choice(matches)
        return text[:m.start()] + value + text[m.end():]
    return op


def scale_number(text, rng):
    matches = numbers_outside_comments(text)
    if not matches:
        return None
    m = rng.choice(matches)
    return text[:m.start()] + repr(float(m.group(0)) * rng.uniform(0.5, 1.5)) + text[m.end():]


def delete_line(text, rng):
    lines = text.splitlines(True)
    if len(lines) < 2:
        return None
    del lines[rng.randrange(len(lines))]
    return "".join(lines)


def swap_lines(text, rng):
    lines = text.splitlines(True)
    if len(lines) < 3:
        return None
    i = rng.randrange(len(lines) - 1)
    lines[i], lines[i + 1] = lines[i + 1], lines[i]
    return "".join(lines)


def truncate_anywhere(text, rng):
    return text[:rng.randrange(1, max(2, len(text)))]


def insert_garbage(text, rng):
    i = rng.randrange(len(text))
    return text[:i] + rng.choice(["\x00", "\xff", "{", "]", ":", "'", "\t", "@@", "- ", "&a *a"]) + text[i:]


YAML_KEY_LINE = re.compile(r"^(\s*)([A-Za-z_][\w.]*):\s*\S.*$", re.M)


def duplicate_yaml_key(text, rng):
    """Repeats a 'key: value' line right after itself: the same key twice in one mapping."""
    matches = list(YAML_KEY_LINE.finditer(text))
    if not matches:
        return None
    m = rng.choice(matches)
    return text[:m.end()] + "\n" + m.group(0) + text[m.end():]


def duplicate_flow_key(text, rng):
    """Repeats the first entry of a flow mapping {a: 1, ...} inside it."""
    matches = list(re.finditer(r"\{\s*([A-Za-z_][\w.]*):\s*([^,}]+)", text))
    if not matches:
        return None
    m = rng.choice(matches)
    return text[:m.end()] + ", " + m.group(1) + ": " + m.group(2) + text[m.end():]


def typo_key(text, rng):
    """Drops one letter of a mapping key (an unknown key, or for a free map a different name)."""
    matches = list(re.finditer(r"(?<=[\s{,])([A-Za-z_]{4,})(?=:)", text))
    if not matches:
        return None
    m = rng.choice(matches)
    k = rng.randrange(1, len(m.group(1)))
    return text[:m.start() + k] + text[m.start() + k + 1:]


def typo_parameter_name(text, rng):
    """Misspells a parameter name a stream maps a slot to (imu.misalignment -> imu.misalignmnet)."""
    matches = list(re.finditer(r"(?<=: )(imu|odometer|gps|magnetometer)\.([a-z_]{5,})(?=[,}])", text))
    if not matches:
        return None
    m = rng.choice(matches)
    name = m.group(2)
    return text[:m.start(2)] + name[:-2] + name[-1] + name[-2] + text[m.end(2):]


# CSV operators. Row 0 is the header where there is one.
def csv_rows(text):
    return text.split("\n")[:-1] if text.endswith("\n") else text.split("\n")


def csv_time(value, header=True):
    def op(text, rng):
        rows = csv_rows(text)
        first = 1 if header else 0
        if len(rows) <= first:
            return None
        r = rng.randrange(first, len(rows))
        cells = rows[r].split(",")
        cells[0] = value
        rows[r] = ",".join(cells)
        return "\n".join(rows) + "\n"
    return op


def csv_value(value, header=True):
    """A value (not the time) of a random row."""
    def op(text, rng):
        rows = csv_rows(text)
        first = 1 if header else 0
        if len(rows) <= first or len(rows[first].split(",")) < 2:
            return None
        r = rng.randrange(first, len(rows))
        cells = rows[r].split(",")
        cells[rng.randrange(1, len(cells))] = value
        rows[r] = ",".join(cells)
        return "\n".join(rows) + "\n"
    return op


def csv_drop_cell(header=True):
    def op(text, rng):
        rows = csv_rows(text)
        first = 1 if header else 0
        if len(rows) <= first:
            return None
        r = rng.randrange(first, len(rows))
        cells = rows[r].split(",")
        del cells[rng.randrange(len(cells))]
        rows[r] = ",".join(cells)
        return "\n".join(rows) + "\n"
    return op


def csv_duplicate_row(header=True):
    def op(text, rng):
        rows = csv_rows(text)
        first = 1 if header else 0
        if len(rows) <= first:
            return None
        r = rng.randrange(first, len(rows))
        rows.insert(r, rows[r])
        return "\n".join(rows) + "\n"
    return op


def csv_swap_rows(header=True):
    def op(text, rng):
        rows = csv_rows(text)
        first = 1 if header else 0
        if len(rows) < first + 2:
            return None
        r = rng.randrange(first, len(rows) - 1)
        rows[r], rows[r + 1] = rows[r + 1], rows[r]
        return "\n".join(rows) + "\n"
    return op


def csv_cut_last_row(text, rng):
    """Cuts the file inside the last number of its last row, without a line end (a write interrupted)."""
    body = text.rstrip("\n")
    last = body.rfind(",")
    if last < 0 or len(body) - last < 4:
        return None
    return body[:rng.randrange(last + 2, len(body))]


def csv_shift_times(offset):
    """Shifts every stamp (a clock offset): with a large offset the stream no longer overlaps the master."""
    def op(text, rng):
        rows = csv_rows(text)
        out = [rows[0]]
        for row in rows[1:]:
            cells = row.split(",")
            cells[0] = "%.9f" % (float(cells[0]) + offset)
            out.append(",".join(cells))
        return "\n".join(out) + "\n"
    return op


def header_only(text, rng):
    return text.split("\n")[0] + "\n"


def byte_flip(data, rng):
    data = bytearray(data)
    for _ in range(rng.randint(1, 4)):
        data[rng.randrange(len(data))] = rng.randrange(256)
    return bytes(data)


def byte_truncate(data, rng):
    return data[:rng.randrange(len(data))]


def bag_string_length(data, rng):
    """Changes the frame_id length prefix of one message (the u32 after seq, sec, nsec): the fields after it shift."""
    starts = [m.start() for m in re.finditer(b"imu_link|gps", data)]
    if not starts:
        return None
    at = rng.choice(starts) - 4
    length = int.from_bytes(data[at:at + 4], "little")
    new = rng.choice([v for v in (0, 1, length - 1, length + 1, length + 4, length + 8, 200) if v != length and v >= 0])
    return data[:at] + new.to_bytes(4, "little") + data[at + 4:]


def bag_message_length(data, rng):
    """Changes the u32 data length of one record (the bytes that follow are read as a different record)."""
    starts = [m.start() for m in re.finditer(b"\x04\x00\x00\x00op=\x02", data)]
    if not starts:
        return None
    # Header length u32 precedes "op" field; data length follows the header.
    at = rng.choice(starts) - 4
    header_len = int.from_bytes(data[at:at + 4], "little")
    data_at = at + 4 + header_len
    length = int.from_bytes(data[data_at:data_at + 4], "little")
    new = rng.choice([length + 1, length - 1, length + 100, 0xFFFFFFF0, 3])
    return data[:data_at] + new.to_bytes(4, "little") + data[data_at + 4:]


# Operators per input kind: (name, function, clearly_bad). Neutral operators may be accepted, never crash.
YAML_OPS = [
    ("duplicate key", duplicate_yaml_key, True),
    ("duplicate flow key", duplicate_flow_key, True),
    ("number -> .nan", replace_number(".nan"), True),
    ("number -> nan", replace_number("nan"), True),
    ("number -> 1e308", replace_number("1e308"), True),
    ("number -> -9.2e18", replace_number("-9.2e18"), True),
    ("number -> 1e-300", replace_number("1e-300"), False),
    ("number -> 0", replace_number("0"), False),
    ("number -> -1", replace_number("-1"), False),
    ("number scaled", scale_number, False),
    ("key typo", typo_key, False),
    ("line deleted", delete_line, False),
    ("lines swapped", swap_lines, False),
    ("truncated", truncate_anywhere, False),
    ("garbage inserted", insert_garbage, False),
]
ESTIMATOR_OPS = YAML_OPS + [("parameter name typo", typo_parameter_name, True)]
STREAM_OPS = [
    ("last row cut mid-number", csv_cut_last_row, True),
    ("value -> nan", csv_value("nan"), True),
    ("value -> 1e308", csv_value("1e308"), True),
    ("value -> text", csv_value("abc"), True),
    ("time -> 9.3e9", csv_time("9300000000"), True),
    ("time -> 9223372036.9", csv_time("9223372036.900000000"), True),
    ("cell dropped", csv_drop_cell(), True),
    # A repeated identical row is a duplicated message: the reader drops and counts it (docs/recording-format.md).
    ("row duplicated (counted skip)", csv_duplicate_row(), False),
    ("rows swapped", csv_swap_rows(), True),
    ("times shifted +1e6 s", csv_shift_times(1e6), True),
    ("times shifted +2 s", csv_shift_times(2.0), False),
    ("header only", header_only, False),
    ("value scaled", scale_number, False),
    ("byte garbage", insert_garbage, False),
]
# The CSV importer skips a repeated time and counts it (docs/import-csv.md); a shift moves every stream of the file.
CSV_LOG_OPS = [op for op in STREAM_OPS if op[0] != "times shifted +1e6 s"]
OPTIODOM_RUN_OPS = [
    ("time -> 9.3e9", csv_time("9300000000", False), True),
    ("time -> 1e300", csv_time("1e300", False), True),
    ("value -> nan", csv_value("nan", False), True),
    ("value -> text", csv_value("abc", False), True),
    ("cell dropped", csv_drop_cell(False), True),
    ("row duplicated", csv_duplicate_row(False), True),
    ("rows swapped", csv_swap_rows(False), True),
    ("value scaled", scale_number, False),
    ("line deleted", delete_line, False),
    ("truncated", truncate_anywhere, False),
    ("garbage inserted", insert_garbage, False),
]
def metadata_value(value, keys):
    """The value of one of `keys` (the keys the importer reads; N, L, ... are accepted and not used)."""
    def op(text, rng):
        lines = text.split("\n")
        rows = [i for i, l in enumerate(lines) if l.split(",")[0] in keys]
        i = rng.choice(rows)
        cells = lines[i].split(",")
        cells[1] = value
        lines[i] = ",".join(cells)
        return "\n".join(lines)
    return op


USED_KEYS = ("ngear", "encRes", "Li", "Di", "Thi")
OPTIODOM_METADATA_OPS = [
    ("key line duplicated", csv_duplicate_row(False), True),
    ("value -> 9.2e18", metadata_value("9.2e18", USED_KEYS), True),
    ("value -> nan", metadata_value("nan", USED_KEYS), True),
    ("value -> -1", metadata_value("-1", USED_KEYS[:4]), True),
    ("key typo", lambda t, r: re.sub(r"^encRes", "encres", t, flags=re.M), True),
    ("line deleted", delete_line, False),
    ("value scaled", scale_number, False),
    ("garbage inserted", insert_garbage, False),
]
BAG_OPS = [
    ("string length prefix changed", bag_string_length, True),
    ("record length changed", bag_message_length, False),
    ("bytes flipped", byte_flip, False),
    ("truncated", byte_truncate, False),
]


def mcap_message_length(data, rng):
    """Changes the u64 length of one Message record (opcode 0x05; the seed's messages have sequence 7)."""
    starts = [m.start() for m in re.finditer(b"\x05.{8}[\x01\x02]\x00\x07\x00\x00\x00", data, re.S)]
    if not starts:
        return None
    at = rng.choice(starts) + 1
    length = int.from_bytes(data[at:at + 8], "little")
    new = rng.choice([length + 1, length - 1, length + 100, 2 ** 63, 3])
    return data[:at] + new.to_bytes(8, "little") + data[at + 8:]


MCAP_OPS = [
    ("string length prefix changed", bag_string_length, True),
    ("record length changed", mcap_message_length, False),
    ("bytes flipped", byte_flip, False),
    ("truncated", byte_truncate, False),
]
# A rosbag2 SQLite file: the messages are blobs inside the database pages; a flipped byte may hit SQLite's own
# structure (a corrupt database) or a message.
DB3_OPS = [
    ("string length prefix changed", bag_string_length, True),
    ("bytes flipped", byte_flip, False),
    ("truncated", byte_truncate, False),
]
BINARY_KINDS = ("ROS 1 bag", "ROS 2 MCAP", "ROS 2 SQLite")


class Seeds:
    """The seed files of one campaign, written under `root`."""

    def __init__(self, root, seeds_tool):
        self.root = root
        subprocess.run([seeds_tool, root], check=True, stdout=subprocess.DEVNULL)
        self.rec = os.path.join(root, "rec")
        self.bag = os.path.join(root, "seed.bag")
        self.mcap = os.path.join(root, "seed.mcap")
        self.db3 = os.path.join(root, "seed.db3")
        self.estimator = os.path.join(REPO, "configs", "atv_calibration.yaml")
        with open(os.path.join(REPO, "scenarios", "indoor_diffdrive_slip.yaml")) as f:
            scenario = re.sub(r"^duration_s: .*$", "duration_s: 1.0", f.read(), flags=re.M)
        # Model paths absolute (the mutant lives elsewhere); IMU and encoders only (no rendering, no laser).
        scenario = scenario.replace("../models/", os.path.join(REPO, "models") + "/")
        scenario = scenario[:scenario.index("  laser:")] + scenario[scenario.index("effects:"):]
        self.scenario = self.write("scenario.yaml", scenario)
        self.optiodom_run = self.write("set_run-01.csv", optiodom_run())
        self.optiodom_metadata = self.write("set_metadata.csv", OPTIODOM_METADATA)
        self.csv_log = self.write("log.csv", CSV_LOG)
        self.csv_map = self.write("map.yaml", CSV_MAP)
        # One calibration case on the synthetic recording (paths absolute: the mutant lives elsewhere).
        self.suite = self.write("suite.yaml", (
            "suite: mutation\n"
            "cases:\n"
            "  - name: synthetic_calibration\n"
            "    mode: calibrate\n"
            "    recording: %s\n"
            "    config: %s\n"
            "    checks:\n"
            "      - {metric: metrics.ate_m, bound: \"<= 10\"}\n"
            "      - {metric: metrics.rpe_trans_m, bound: \"<= 2 * metrics.ate_m + 10\"}\n"
            "      - {metric: calibration.measurements.gps.rejected, bound: \">= 100000\", open: \"a reason\"}\n")
            % (self.rec, self.estimator))

    def write(self, name, text):
        path = os.path.join(self.root, name)
        with open(path, "w") as f:
            f.write(text)
        return path


def run(command, timeout):
    try:
        p = subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, ""
    return p.returncode, p.stderr.decode("utf-8", "replace")


def classify(code, err, names, bad):
    if code is None:
        return "hang"
    if code < 0 or code > 2 or any(t in err for t in CRASH_TEXT):
        return "crash"
    if code == 0:
        return "silent" if bad else "accepted"
    lines = [l for l in err.splitlines() if l.strip() and ": warning: " not in l and not l.startswith("\r")]
    lines = [l for l in lines if not re.match(r"^(calibrate|simulate|track): |^regress \[", l)]  # progress lines
    if code == 2 and len(lines) == 1 and any(n in lines[0] for n in names):
        return "clean"
    # regress reports a failed check in its table on standard output, with no line on standard error.
    if code == 1 and len(lines) <= 1 and not bad:
        return "failure"
    return "unclean"


class Campaign:
    def __init__(self, args, seeds, work):
        self.args = args
        self.seeds = seeds
        self.work = work
        self.rng = random.Random(args.seed)
        self.rows = {}
        self.failures = []

    def mutant_dir(self, kind, i):
        d = os.path.join(self.work, "%s-%03d" % (kind.replace(" ", "_"), i))
        os.makedirs(d)
        return d

    def text_kind(self, kind, ops, seed_path, build):
        """`build(mutant_dir, mutated_path)` copies what the command needs and returns (command, names)."""
        with open(seed_path, "rb") as f:
            original = f.read()
        binary = kind in BINARY_KINDS
        for i in range(self.args.per_kind):
            name, op, bad = ops[i % len(ops)]
            mutated = None
            for _ in range(20):
                mutated = op(original, self.rng) if binary else op(original.decode(), self.rng)
                if mutated is not None and mutated != (original if binary else original.decode()):
                    break
                mutated = None
            if mutated is None:
                continue
            d = self.mutant_dir(kind, i)
            path = os.path.join(d, os.path.basename(seed_path))
            command, names = build(d, path)
            with open(path, "wb") as f:
                f.write(mutated if binary else mutated.encode("utf-8", "surrogateescape"))
            code, err = run(command, self.args.timeout)
            outcome = classify(code, err, names, bad)
            row = self.rows.setdefault(kind, {})
            row[outcome] = row.get(outcome, 0) + 1
            if outcome in ("silent", "crash", "hang", "unclean"):
                self.failures.append((kind, name, outcome, code, d, err.strip().splitlines()[-1:] if err else ""))
            if outcome in ("accepted", "clean"):
                shutil.rmtree(d, ignore_errors=True)

    def copy_recording(self, d):
        rec = os.path.join(d, "rec")
        shutil.copytree(self.seeds.rec, rec)
        return rec

    def all_kinds(self):
        roamlab = self.args.roamlab
        s = self.seeds

        def calibrate(rec, config, d):
            return [roamlab, "calibrate", rec, "--config", config, "--out", os.path.join(d, "out"), "--quiet"]

        # The recording's own files are mutated in place inside a copy: the mutated path is inside d/rec.
        def in_recording(file_name, command):
            def build(d, path):
                rec = self.copy_recording(d)
                target = os.path.join(rec, file_name)
                os.remove(target)
                os.symlink(path, target)
                return command(rec, d), [file_name, os.path.basename(path)]
            return build

        self.text_kind("recording.yaml", YAML_OPS, os.path.join(s.rec, "recording.yaml"),
                       in_recording("recording.yaml", lambda rec, d: [roamlab, "init", rec, "--out",
                                                                      os.path.join(d, "est.yaml"), "--quiet"]))
        for stream in ("gps.csv", "imu.csv"):
            self.text_kind("stream CSV " + stream, STREAM_OPS, os.path.join(s.rec, stream),
                           in_recording(stream, lambda rec, d: calibrate(rec, s.estimator, d)))
        self.text_kind("estimator YAML", ESTIMATOR_OPS, s.estimator,
                       lambda d, path: (calibrate(s.rec, path, d), [os.path.basename(path)]))
        self.text_kind("scenario YAML", YAML_OPS, s.scenario,
                       lambda d, path: ([roamlab, "simulate", path, "--out", os.path.join(d, "out"), "--quiet"],
                                        [os.path.basename(path)]))

        def optiodom(d, path):
            run_csv = path if path.endswith("run-01.csv") else s.optiodom_run
            meta = path if path.endswith("metadata.csv") else s.optiodom_metadata
            return ([roamlab, "import", "optiodom", run_csv, "--metadata", meta, "--out", os.path.join(d, "out"),
                     "--quiet"], [os.path.basename(path)])

        self.text_kind("OptiOdom run", OPTIODOM_RUN_OPS, s.optiodom_run, optiodom)
        self.text_kind("OptiOdom metadata", OPTIODOM_METADATA_OPS, s.optiodom_metadata, optiodom)
        def import_bag(d, path):
            return ([roamlab, "import", "rosbag", path, "--out", os.path.join(d, "out"), "--quiet"],
                    [os.path.basename(path)])

        self.text_kind("ROS 1 bag", BAG_OPS, s.bag, import_bag)
        self.text_kind("ROS 2 MCAP", MCAP_OPS, s.mcap, import_bag)
        self.text_kind("ROS 2 SQLite", DB3_OPS, s.db3, import_bag)
        self.text_kind("regress suite", YAML_OPS, s.suite,
                       lambda d, path: ([roamlab, "regress", path, "--out", os.path.join(d, "out"), "--jobs", "1",
                                         "--quiet"], [os.path.basename(path)]))

        def csv_import(d, path):
            log = path if path.endswith(".csv") else s.csv_log
            mapping = path if path.endswith(".yaml") else s.csv_map
            return ([roamlab, "import", "csv", log, "--map", mapping, "--out", os.path.join(d, "out"), "--quiet"],
                    [os.path.basename(path)])

        self.text_kind("CSV import mapping", YAML_OPS, s.csv_map, csv_import)
        self.text_kind("CSV import log", CSV_LOG_OPS, s.csv_log, csv_import)

    def table(self):
        columns = ["clean", "unclean", "failure", "accepted", "silent", "crash", "hang"]
        lines = ["| input kind | mutants | " + " | ".join(columns) + " |",
                 "|---|---|" + "---|" * len(columns)]
        totals = {c: 0 for c in columns}
        for kind, row in self.rows.items():
            n = sum(row.values())
            lines.append("| %s | %d | " % (kind, n) + " | ".join(str(row.get(c, 0)) for c in columns) + " |")
            for c in columns:
                totals[c] += row.get(c, 0)
        lines.append("| **all** | %d | " % sum(totals.values()) + " | ".join(str(totals[c]) for c in columns) + " |")
        return "\n".join(lines), totals


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--roamlab", required=True)
    parser.add_argument("--seeds-tool", required=True)
    parser.add_argument("--per-kind", type=int, default=45)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--timeout", type=float, default=60.0)
    parser.add_argument("--work", help="keep the mutants that were not cleanly handled here (default: a temp dir)")
    parser.add_argument("--markdown", help="also write the table to this file")
    parser.add_argument("--list-failures", action="store_true", help="print every unclean, silent, crash, hang")
    args = parser.parse_args()
    work = args.work or tempfile.mkdtemp(prefix="roamlab-mutate-")
    os.makedirs(work, exist_ok=True)
    seeds = Seeds(os.path.join(work, "seeds"), args.seeds_tool)
    campaign = Campaign(args, seeds, work)
    campaign.all_kinds()
    table, totals = campaign.table()
    print(table)
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write(table + "\n")
    if args.list_failures:
        for kind, name, outcome, code, d, last in campaign.failures:
            print("%-8s %-22s %-30s exit %s  %s  %s" % (outcome, kind, name, code, d, last))
    if not args.work:
        shutil.rmtree(work, ignore_errors=True)
    return 1 if totals["silent"] + totals["crash"] + totals["hang"] > 0 else 0


if __name__ == "__main__":
    sys.exit(main())
