#!/usr/bin/python3
# Equal-time table of the tracing filter (issue #18): for each scene, N and seed it renders
#   - plain MC at N spp,
#   - the tracing filter at N spp for each variant "radius floor [partials]" (time: render +
#     gather; partials: --tf-partials, left to mcdenoise's default when not given),
#   - plain MC at the spp the filter's time buys (N x filter's time / plain's time at N),
#   - the pivot filter on a plain N-spp frame (render --layers pivot, denoise --method pivot;
#     time: render + denoise),
# and prints a markdown table of relMSE against `render --reference` (the cache that tests
# and `bench quality` use), then one of the brightness over the reference's: the frame mean
# and, on relief-abc, its letters (the mask of scripts/pivot_letters.py, scaled to the size).
# Times are the figures mcdenoise prints (not process wall time); they vary with load.
# Usage: /usr/bin/python3 scripts/tracing_measure.py [-h] [--mcdenoise PATH] [--size WxH]
#   [--scenes A,B] [--spp 4,16] [--seeds 1,2] [--variant "RADIUS FLOOR [PARTIALS]"]... [--reference-spp S]
#   [--repeat R] [--out DIR]
# Needs numpy and python3-openimageio (Debian). Not part of CI.
import argparse
import os
import re
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio


def Run(args):
    """Run one mcdenoise command; stop with its own message if it fails."""
    done = subprocess.run(args, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"failed ({done.returncode}): {' '.join(args)}\n{done.stdout}{done.stderr}")
    return done.stdout


def Find(pattern, text, what):
    """The first group of pattern in an mcdenoise output, as a float."""
    match = re.search(pattern, text)
    if not match:
        sys.exit(f"no {what} in mcdenoise's output:\n{text}")
    return float(match.group(1))


def RenderSeconds(out):
    """The render's time, the gather included, from
    "OUT.exr: scene WxH at N spp, K layers, T s (R M samples/s)". T has two decimals, too
    coarse for small frames (0.01-0.02 s at 128x128); W x H x N / R has three digits there.
    Take whichever of the two is the more precise."""
    match = re.search(r" ([0-9]+)x([0-9]+) at ([0-9]+) spp, [0-9]+ layers, ([0-9.]+) s "
                      r"\(([0-9.]+) M samples/s\)", out)
    if not match:
        sys.exit(f"no render time in mcdenoise's output:\n{out}")
    w, h, spp = (int(match.group(i)) for i in (1, 2, 3))
    seconds, rate = float(match.group(4)), float(match.group(5))
    if rate > 0 and (seconds <= 0 or 0.005 / rate < 0.005 / seconds):
        return w * h * spp / (rate * 1e6)
    return seconds


def Timed(args, repeat, seconds):
    """Run a command repeat times (the same seed gives the same frame) and keep the fastest
    time, seconds(output), the least disturbed by the other jobs on the machine."""
    runs = [Run(args) for _ in range(repeat)]
    times = [seconds(out) for out in runs]
    best = times.index(min(times))
    return runs[best], times[best]


def DenoiseSeconds(out):
    # "OUT.exr: pivot in T ms (...)".
    return Find(r"in ([0-9.]+) ms", out, "denoise time") / 1e3


def ReadColor(path):
    """The color layer of an EXR frame (R G B, or color.R ... in other writers) as float64."""
    inp = oiio.ImageInput.open(path)
    if not inp:
        sys.exit(f"cannot open {path}: {oiio.geterror()}")
    names = list(inp.spec().channelnames)
    data = inp.read_image(oiio.FLOAT)
    inp.close()
    rgb = ["R", "G", "B"] if "R" in names else ["color.R", "color.G", "color.B"]
    if not all(c in names for c in rgb):
        sys.exit(f"{path} has no color layer (channels {names})")
    return data[:, :, [names.index(c) for c in rgb]].astype(np.float64)


class Reference:
    """A converged frame, its letters' mask and the figures every image is measured by."""

    def __init__(self, path):
        self.path = path
        self.color = ReadColor(path)
        h, w = self.color.shape[:2]
        # pivot_letters.py's band, rows 50-85 and columns 8-119 of 128, scaled to the size.
        self.band = (slice(50 * h // 128, 86 * h // 128), slice(8 * w // 128, 120 * w // 128))
        bandLum = self.color[self.band].mean(axis=2)
        # The letters: the band's pixels brighter than its median in the reference.
        self.letters = bandLum > np.median(bandLum)
        self.lettersMean = bandLum[self.letters].mean()
        self.frameMean = self.color.mean()

    def Measure(self, binary, path):
        """relMSE (from `mcdenoise compare`), letters and frame mean over the reference's."""
        out = Run([binary, "compare", path, self.path])
        relMse = Find(r"relMSE ([0-9.eE+-]+|inf|nan)", out, "relMSE")
        image = ReadColor(path)
        # The same relMSE (host/metrics.cpp: mean over pixels and R G B of
        # (x - r)^2 / (r^2 + 0.01)), to catch a change in compare's definition or output.
        check = np.mean((image - self.color) ** 2 / (self.color**2 + 0.01))
        if np.isfinite(relMse) and abs(check - relMse) > 1e-4 * relMse + 1e-9:
            print(f"warning: {path}: compare's relMSE {relMse:.6g}, numpy's {check:.6g}",
                  file=sys.stderr)
        letters = image[self.band].mean(axis=2)[self.letters].mean() / self.lettersMean
        return relMse, letters, image.mean() / self.frameMean


class Cell:
    """Figures of one table cell, averaged over the seeds."""

    def __init__(self):
        self.runs = []

    def Add(self, seconds, measured, **extra):
        self.runs.append(dict(seconds=seconds, relMse=measured[0], letters=measured[1],
                              mean=measured[2], **extra))

    def __getattr__(self, key):
        if key == "runs":
            raise AttributeError(key)
        return sum(r[key] for r in self.runs) / len(self.runs)


def Figure(x):
    """Three significant digits, as the notes print relMSE."""
    return f"{x:#.3g}".rstrip(".") if x < 1000 else f"{x:.0f}"


def IntList(text, name, least):
    """A comma-separated list of integers, each at least least; exits naming the option."""
    try:
        values = [int(v) for v in text.split(",")]
    except ValueError:
        sys.exit(f"{name} {text}: expected integers separated by commas")
    if min(values) < least:
        sys.exit(f"{name} {text}: each must be at least {least}")
    return values


def Seconds(x):
    """A time with three decimals below a second (small frames take hundredths)."""
    return f"{x:.3f} s" if x < 1 else f"{x:.2f} s"


def main():
    parser = argparse.ArgumentParser(
        description="Equal-time table of the tracing filter (issue #18): relMSE and "
        "brightness of plain MC, the tracing filter and the pivot filter against cached "
        "references.")
    parser.add_argument("--mcdenoise", default="build/mcdenoise", help="mcdenoise binary")
    parser.add_argument("--size", default="128x128", help="frame size WxH")
    parser.add_argument("--scenes", default="relief-abc,double-textured,glossy-cornell")
    parser.add_argument("--spp", default="4,16", help="N: spp of plain MC and the filter")
    parser.add_argument("--seeds", default="1", help="seeds to average, comma-separated")
    parser.add_argument("--variant", action="append",
                        help='tracing filter "RADIUS SELF_FLOOR [PARTIALS]" (repeat; '
                        'PARTIALS: --tf-partials, mcdenoise\'s default when left out; default '
                        '"3 0.5" and "3 0.9")')
    parser.add_argument("--reference-spp", type=int, default=2048,
                        help="spp of the cached references (render --reference)")
    parser.add_argument("--repeat", type=int, default=1,
                        help="run each timed command this many times, keep the fastest "
                        "(the equal-time spp follow these times)")
    parser.add_argument("--out", default="out/tracing-measure",
                        help="folder for the frames and the references' copies")
    opt = parser.parse_args()
    binary = opt.mcdenoise
    if not os.access(binary, os.X_OK):
        sys.exit(f"--mcdenoise {binary}: not an executable (build the mcdenoise target)")
    if not re.fullmatch(r"[0-9]+x[0-9]+", opt.size):
        sys.exit(f"--size {opt.size}: expected WxH")
    scenes = opt.scenes.split(",")
    spps, seeds = IntList(opt.spp, "--spp", 1), IntList(opt.seeds, "--seeds", 0)
    variants = []
    for v in opt.variant or ["3 0.5", "3 0.9"]:
        parts = v.split()
        if len(parts) not in (2, 3):
            sys.exit(f'--variant "{v}": expected "RADIUS SELF_FLOOR [PARTIALS]"')
        try:
            variants.append((int(parts[0]), float(parts[1]),
                             int(parts[2]) if len(parts) == 3 else None))
        except ValueError:
            sys.exit(f'--variant "{v}": expected an integer radius, a number floor and an '
                     'integer partials')
    if opt.repeat < 1:
        sys.exit(f"--repeat {opt.repeat}: expected at least 1")
    os.makedirs(opt.out, exist_ok=True)

    def Frame(name):
        return os.path.join(opt.out, name + ".exr")

    rows = []  # (scene, N, {column: Cell})
    for scene in scenes:
        # The reference: rendered into the shared cache once, copied here.
        refPath = Frame(f"ref-{scene}-{opt.size}-{opt.reference_spp}spp")
        print(Run([binary, "render", "--reference", "--scene", scene, "--size", opt.size,
                   "--spp", str(opt.reference_spp), "-o", refPath]).strip(), file=sys.stderr)
        ref = Reference(refPath)
        for n in spps:
            cells = {}

            def Get(key):
                return cells.setdefault(key, Cell())

            for seed in seeds:
                base = [binary, "render", "--scene", scene, "--size", opt.size,
                        "--seed", str(seed)]
                tag = f"{scene}-{n}spp-seed{seed}"
                # Plain MC at N: the baseline and the time the equal-time spp scale from.
                path = Frame(f"{tag}-plain")
                _, plainSeconds = Timed(base + ["--spp", str(n), "-o", path], opt.repeat,
                                        RenderSeconds)
                Get("plain").Add(plainSeconds, ref.Measure(binary, path))
                for radius, floor, partials in variants:
                    name = f"r{radius}-f{floor}" + (f"-p{partials}" if partials else "")
                    path = Frame(f"{tag}-tf-{name}")
                    extra = ["--tf-partials", str(partials)] if partials else []
                    out, seconds = Timed(base + ["--spp", str(n), "--tracing-filter",
                                                 "--tf-radius", str(radius), "--tf-self-floor",
                                                 str(floor)] + extra + ["-o", path],
                                         opt.repeat, RenderSeconds)
                    # The gather's share of render + gather, as mcdenoise prints it.
                    share = Find(r"gather [0-9.]+ s \(([0-9.]+)%\)", out, "gather share")
                    Get(("tf", radius, floor, partials)).Add(seconds, ref.Measure(binary, path),
                                                             share=share / 100)
                    # Plain MC at the spp the filter's time buys (time linear in spp).
                    m = max(n, round(n * seconds / plainSeconds))
                    path = Frame(f"{tag}-plain-equal-{name}")
                    out = Run(base + ["--spp", str(m), "-o", path])
                    Get(("equal", radius, floor, partials)).Add(RenderSeconds(out),
                                                                ref.Measure(binary, path), spp=m)
                # The pivot filter on a plain N-spp frame with the pivot layer.
                path = Frame(f"{tag}-pivot-in")
                _, seconds = Timed(base + ["--spp", str(n), "--layers", "pivot", "-o", path],
                                   opt.repeat, RenderSeconds)
                _, denoise = Timed([binary, "denoise", "--method", "pivot", path, "-o",
                                    Frame(f"{tag}-pivot")], opt.repeat, DenoiseSeconds)
                seconds += denoise
                Get("pivot").Add(seconds, ref.Measure(binary, Frame(f"{tag}-pivot")))
            rows.append((scene, n, cells))
            print(f"done {scene} N={n}", file=sys.stderr)

    # The relMSE table: each tracing filter cell gives its ratio to plain MC at equal time.
    head = ["scene", "N", "plain N"]
    for radius, floor, partials in variants:
        head += [f"tf r{radius} floor {floor}" + (f" partials {partials}" if partials else ""),
                 "plain at its time"]
    head += ["pivot"]
    print(f"relMSE against the {opt.reference_spp}-spp references, {opt.size}, "
          f"seeds {opt.seeds} (mean); time of render (+ gather, + denoise)"
          f"{f', fastest of {opt.repeat}' if opt.repeat > 1 else ''}\n")
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for scene, n, cells in rows:
        c = cells["plain"]
        line = [scene, str(n), f"{Figure(c.relMse)} ({Seconds(c.seconds)})"]
        for radius, floor, partials in variants:
            t = cells[("tf", radius, floor, partials)]
            e = cells[("equal", radius, floor, partials)]
            # The ratio of the means over the seeds; with several, the per-seed range too.
            ratio = f"{t.relMse / e.relMse:.2f} of plain's"
            if len(seeds) > 1:
                each = [a["relMse"] / b["relMse"] for a, b in zip(t.runs, e.runs)]
                ratio += f", seeds {min(each):.2f}-{max(each):.2f}"
            line.append(f"**{Figure(t.relMse)}** ({Seconds(t.seconds)}, gather "
                        f"{100 * t.share:.0f}%; {ratio})")
            line.append(f"{Figure(e.relMse)} ({e.spp:.0f} spp, {Seconds(e.seconds)})")
        c = cells["pivot"]
        line.append(f"{Figure(c.relMse)} ({Seconds(c.seconds)})")
        print("| " + " | ".join(line) + " |")

    # The brightness table: frame mean (and relief-abc's letters) over the reference's.
    print("\nbrightness over the reference's: frame mean (letters on relief-abc)\n")
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for scene, n, cells in rows:
        keys = ["plain"]
        for radius, floor, partials in variants:
            keys += [("tf", radius, floor, partials), ("equal", radius, floor, partials)]
        keys.append("pivot")
        line = [scene, str(n)]
        for key in keys:
            c = cells[key]
            line.append(f"{c.mean:.3f}" + (f" (letters {c.letters:.3f})"
                                           if scene == "relief-abc" else ""))
        print("| " + " | ".join(line) + " |")


if __name__ == "__main__":
    main()
