"""python3 -m rthdist A B: the CLI (tools/cli) through the Python package.

Same inputs, options and exit codes as `rthdist`, and a subset of its
summary and --json keys (docs/python.md "Command line": no certificate
block, hd95 block or normalized values), for what the package binds: --json, --directed, --backend, --device, --bits,
--radius-growth, --threads, --per-point (--percentile, --histogram-bins and
--range each imply it, as in the CLI), --las-classes, --validation,
--list-devices, --version. The picture and per-point file outputs (--out-ply,
--png, ...) and --verify are the CLI's only. The JSON is strict: a
non-finite number is written as null, as the CLI writes it.

Exit codes: 0 ok; 1 internal error; 2 usage; 3 bad input (file, empty set,
NaN); 4 no usable Vulkan device; 130 interrupted.
"""

import argparse
import json
import math
import re
import sys
import time

import numpy as np

import rthdist

EXIT_OK, EXIT_INTERNAL, EXIT_USAGE, EXIT_INPUT, EXIT_DEVICE, EXIT_INTERRUPT = 0, 1, 2, 3, 4, 130


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        self.print_usage(sys.stderr)
        sys.stderr.write(f"rthdist: {message}\nTry 'python3 -m rthdist --help'.\n")
        sys.exit(EXIT_USAGE)


# The CLI's number grammar (tools/cli/args.cpp, std::from_chars): an optional
# leading '-', no '+', no spaces, no '_' (which Python's int() and float() take).
_INTEGER = re.compile(r"-?[0-9]+")
_NUMBER = re.compile(r"-?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][-+]?[0-9]+)?")


def _integer(text):
    if not _INTEGER.fullmatch(text):
        raise ValueError(text)
    return int(text)


def _number(text):
    if not _NUMBER.fullmatch(text):
        raise ValueError(text)
    return float(text)


def _ranged(kind, lo, hi, name):
    def parse(text):
        try:
            v = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"option '{name}': '{text}' is not a number") from None
        if not lo <= v <= hi:
            raise argparse.ArgumentTypeError(f"option '{name}': {text} is outside {lo}..{hi}")
        return v

    return parse


def _classes(text):
    try:
        values = [_integer(x) for x in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"option '--las-classes': '{text}' is not a list of integers") from None
    if any(not 0 <= v <= 255 for v in values):
        raise argparse.ArgumentTypeError("option '--las-classes': classes are 0..255")
    return values


def _parser():
    p = _Parser(prog="python3 -m rthdist", description="Exact Hausdorff distance between two 3-D point sets.")
    p.add_argument("a", nargs="?", help="first point set (.ply .xyz .txt .obj .gltf .glb .stl .off .pcd .las, .gz)")
    p.add_argument("b", nargs="?", help="second point set")
    p.add_argument("--json", action="store_true", help="print one JSON object (the CLI's keys)")
    p.add_argument("--directed", action="store_true", help="compute only h(A,B)")
    p.add_argument("--backend", default="auto", choices=["auto", "ray-query", "rt-pipeline", "cpu"])
    p.add_argument("--device", type=_ranged(_integer, 0, 1023, "--device"), default=None, help="Vulkan device index")
    p.add_argument("--bits", type=_ranged(_integer, 0, 8, "--bits"), default=0, help="index bits (0 = auto)")
    p.add_argument("--radius-growth", type=_ranged(_number, 1.1, 16.0, "--radius-growth"), default=2.0)
    p.add_argument("--threads", type=_ranged(_integer, 0, 1024, "--threads"), default=0, help="CPU threads (0 = all)")
    p.add_argument("--per-point", action="store_true", help="per-point distances and their statistics")
    p.add_argument("--percentile", type=_ranged(_number, 0.0, 100.0, "--percentile"), action="append",
                   help="also report this percentile (repeatable)")
    p.add_argument("--histogram-bins", type=_ranged(_integer, 1, 10000, "--histogram-bins"), default=None,
                   help="histogram bins, 1..10000 (default 20)")
    p.add_argument("--range", nargs=2, metavar=("MIN", "MAX"),
                   help="fixed histogram range, finite, 0 <= MIN < MAX (default 0 .. the largest distance)")
    p.add_argument("--las-classes", type=_classes, default=None, help="LAS classes to read, e.g. 2,6")
    p.add_argument("--validation", action="store_true", help="enable the Vulkan validation layer")
    p.add_argument("--list-devices", action="store_true", help="list every Vulkan device")
    p.add_argument("--version", action="store_true")
    return p


def _range(parser, texts):
    """--range MIN MAX as the CLI checks it (tools/cli/args.cpp): finite, 0 <= MIN < MAX, else exit 2."""
    try:
        lo, hi = (_number(t) for t in texts)
    except ValueError:
        lo = hi = math.nan
    if not (math.isfinite(lo) and math.isfinite(hi) and 0.0 <= lo < hi):
        parser.error(f"option '--range' expects finite numbers 0 <= MIN < MAX, got '{texts[0]}' '{texts[1]}'")
    return lo, hi


def _strict(value):
    """value with every non-finite float as None: the CLI's JSON writes NaN and infinities as null."""
    if isinstance(value, dict):
        return {k: _strict(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_strict(v) for v in value]
    if isinstance(value, np.ndarray):
        return _strict(value.tolist())
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, np.integer):
        return int(value)
    return value


def _json_text(value):
    """Standard JSON (RFC 8259: no NaN or Infinity tokens), indented as the CLI's."""
    return json.dumps(_strict(value), indent=2, allow_nan=False) + "\n"


def _fail(code, message):
    sys.stderr.write(f"rthdist: {message}\n")
    return code


def _directed_json(d, query, target):
    if d is None:
        return None
    return {"distance": d.distance, f"{query}_index": d.query_index, f"{target}_index": d.target_index,
            f"{query}_point": d.query_point.tolist(), f"{target}_point": d.target_point.tolist()}


def _precision(points):
    return "float64" if points.dtype == np.float64 else "float32"


def _report(args, a, b, r, load_ms, stats, wall_ms):
    timings = dict(r.timings)
    timings = {"load": load_ms, **{k: timings[k] for k in
               ("setup", "upload", "index", "cull", "search", "refine", "check", "total")}, "wall": wall_ms}
    out = {
        "version": rthdist.__version__,
        "files": {"a": args.a, "b": args.b},
        "points": {"a": len(a), "b": len(b)},
        "precision": {"a": _precision(a), "b": _precision(b)},
        "origin": r.origin.tolist(),
        "backend": r.backend,
        "device": r.device,
        "bits": r.a_to_b.counters["bits"],
        "bits_requested": args.bits,
        "directed": r.directed,
        "hausdorff": r.distance,
        "a_to_b": _directed_json(r.a_to_b, "a", "b"),
        "b_to_a": _directed_json(r.b_to_a, "b", "a"),
        "timings_ms": timings,
        "counters": r.counters,
        "validation": args.validation,
        "validation_messages": r.validation_messages,
    }
    if stats is not None:
        hist = stats["histogram"]
        stats["histogram"] = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in hist.items()}
        out["per_point"] = stats
    return out


def _point(p):
    return "(" + ", ".join(f"{v:g}" for v in p) + ")"


def _summary(args, a, b, r, out):
    lines = [f"rthdist {rthdist.__version__}: backend {r.backend} on {r.device}",
             f"A  {args.a}  ({len(a)} points)", f"B  {args.b}  ({len(b)} points)"]
    lines.append(("h(A,B)" if r.directed else "H(A,B)") + f" = {r.distance:.12g}")
    for label, d, q, t in (("h(A,B)", r.a_to_b, "A", "B"), ("h(B,A)", r.b_to_a, "B", "A")):
        if d is not None:
            lines.append(f"  {label} = {d.distance:.12g}   {q}[{d.query_index}] {_point(d.query_point)} -> "
                         f"{t}[{d.target_index}] {_point(d.target_point)}")
    t = out["timings_ms"]
    lines.append("time (ms)  " + " | ".join(f"{k} {v:.2f}" for k, v in t.items()))
    if "per_point" in out:
        s = out["per_point"]
        lines.append(f"per-point  distances (bbox diagonal of A+B {s['diagonal']:g})")
        for name in ("a_to_b", "b_to_a", "pooled"):
            blk = s[name]
            if blk is None:
                continue
            ps = "  ".join(f"P{p['p']:g} {p['value']:g}" for p in blk["percentiles"])
            lines.append(f"           {name:7s} min {blk['min']:g}  mean {blk['mean']:g}  rms {blk['rms']:g}  "
                         f"max {blk['max']:g}  {ps}")
        lines.append(f"HD95       {r.hd95:.12g} (max of directed P95)")
    return "\n".join(lines) + "\n"


def main(argv=None):
    start = time.perf_counter()
    parser = _parser()
    args = parser.parse_args(argv)
    if args.range is not None:
        args.range = _range(parser, args.range)
    # As in the CLI, each per-point option turns --per-point on.
    per_point = (args.per_point or bool(args.percentile) or args.histogram_bins is not None
                 or args.range is not None)
    if args.version:
        print(f"rthdist {rthdist.__version__}")
        return EXIT_OK
    try:
        if args.list_devices:
            devices = rthdist.list_devices()
            if args.json:
                sys.stdout.write(_json_text(devices))
            else:
                for d in devices:
                    paths = [p for p, ok in (("ray-query", d["ray_query"]), ("rt-pipeline", d["rt_pipeline"])) if ok]
                    print(f"[{d['index']}] {d['name']} ({d['type']}, {d['driver']}): "
                          f"{', '.join(paths) or 'no ray-tracing path'}")
                    for why in d["missing"]:
                        print(f"    {why}")
            return EXIT_OK
        if args.a is None or args.b is None:
            return _fail(EXIT_USAGE, "two input files are needed: A B\nTry 'python3 -m rthdist --help'.")
        t0 = time.perf_counter()
        a = rthdist.load(args.a, las_classes=args.las_classes)
        b = rthdist.load(args.b, las_classes=args.las_classes)
        load_ms = (time.perf_counter() - t0) * 1e3
        r = rthdist.hausdorff(a, b, directed=args.directed, per_point=per_point, backend=args.backend,
                              device=args.device, bits=args.bits, radius_growth=args.radius_growth,
                              threads=args.threads, validation=args.validation)
        stats = None
        if per_point:
            percentiles = [50.0, 90.0, 95.0, 99.0] if not args.percentile else list(args.percentile)
            if 95.0 not in percentiles:
                percentiles.append(95.0)
            stats = r.stats(percentiles=percentiles, bins=args.histogram_bins or 20, range=args.range)
    except (FileNotFoundError, IsADirectoryError, PermissionError) as e:
        return _fail(EXIT_INPUT, f"cannot read '{e.filename}': {e.strerror}")
    except ValueError as e:
        return _fail(EXIT_INPUT, str(e))
    except rthdist.DeviceError as e:
        return _fail(EXIT_DEVICE, str(e))
    except KeyboardInterrupt:
        return _fail(EXIT_INTERRUPT, "interrupted")
    except rthdist.Error as e:
        return _fail(EXIT_INTERNAL, str(e))
    out = _report(args, a, b, r, load_ms, stats, (time.perf_counter() - start) * 1e3)
    sys.stdout.write(_json_text(out) if args.json else _summary(args, a, b, r, out))
    return EXIT_OK


if __name__ == "__main__":
    sys.exit(main())
