#!/usr/bin/python3
"""Measure methods on the real Cycles frames against Open Image Denoise (a peer, not a dependency).

usage: /usr/bin/python3 scripts/realset_measure.py [--scenes a,b] [--frame plain|acc]
           [--run NAME=ARGS ...] [--oidn] [--out DIR] [--mcdenoise PATH]

For each scene of ~/.cache/mcdenoise/realset (<scene>/{plain,acc}.exr, ref/chunkNN.exr) the
reference is the mean of the chunks (written once to DIR/<scene>/ref.exr); its own relMSE
is estimated from two chunks. Each --run denoises the frame with `mcdenoise denoise
<frame> ARGS` (wall time of the process), --oidn with /work/shared/peers/oidn (its filter
time, median of 3 runs); `input` is the frame itself. Every output is measured with
`mcdenoise compare` (relMSE, PSNR, SSIM) and its mean brightness over the reference's.
Prints one markdown table per scene and the geometric mean of relMSE per row name.
"""
import argparse, math, os, re, subprocess, sys, time
import numpy as np
import OpenImageIO as oiio

REALSET = os.path.expanduser('~/.cache/mcdenoise/realset')
OIDN = '/work/shared/peers/oidn/denoise_exr.py'
SCENES = 'still_life,sunlit_room,glossy_lights,fence_grass,motion_blur,product_transparent'


def read_rgb(path):
    inp = oiio.ImageInput.open(path)
    spec = inp.spec()
    names = list(spec.channelnames)
    pixels = inp.read_image(0, spec.nchannels, oiio.FLOAT)
    inp.close()
    for prefix in ('ViewLayer.Combined.', '', 'color.'):
        idx = [names.index(prefix + c) if prefix + c in names else -1 for c in 'RGB']
        if min(idx) >= 0:
            return np.asarray(pixels)[:, :, idx]
    raise SystemExit(f'{path}: no RGB colour among {names[:8]}...')


def write_rgb(path, rgb):
    out = oiio.ImageOutput.create(path)
    out.open(path, oiio.ImageSpec(rgb.shape[1], rgb.shape[0], 3, oiio.FLOAT))
    if not out.write_image(np.ascontiguousarray(rgb, dtype=np.float32)):
        raise SystemExit(f"{path}: {out.geterror()}")
    out.close()


def rel_mse(x, r):
    return float(np.mean((x - r) ** 2 / (r * r + 0.01)))


def reference(scene, out_dir):
    chunks = sorted(f for f in os.listdir(os.path.join(REALSET, scene, 'ref'))
                    if re.fullmatch(r'chunk\d+\.exr', f))
    images = [read_rgb(os.path.join(REALSET, scene, 'ref', c)) for c in chunks]
    mean = sum(images) / len(images)
    path = os.path.join(out_dir, 'ref.exr')
    if not os.path.exists(path):
        write_rgb(path, mean)
    # Two chunks differ by twice one chunk's variance; the mean of n has 1/n of it.
    own = rel_mse(images[0], images[1]) / (2 * len(images))
    return path, mean, len(images), own


def compare(mcd, image, ref_path, ref_mean):
    text = subprocess.run([mcd, 'compare', image, ref_path], capture_output=True,
                          text=True, check=True).stdout
    m = re.search(r'relMSE ([0-9.eE+-]+|inf), PSNR ([0-9.inf-]+) dB, SSIM ([0-9.]+)', text)
    rgb = read_rgb(image)
    return (float(m.group(1)), float(m.group(2)), float(m.group(3)),
            float(np.mean(rgb)) / float(np.mean(ref_mean)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--scenes', default=SCENES)
    ap.add_argument('--frame', default='plain')
    ap.add_argument('--run', action='append', default=[], help='NAME=mcdenoise denoise args')
    ap.add_argument('--oidn', action='store_true')
    ap.add_argument('--out', default='/tmp/realset_measure')
    ap.add_argument('--mcdenoise', default='build/mcdenoise')
    ap.add_argument('--oidn-tool', default=None, help='oidnDenoise to run (denoise_exr.py --oidn)')
    a = ap.parse_args()
    logs = {}
    for scene in a.scenes.split(','):
        out_dir = os.path.join(a.out, scene)
        os.makedirs(out_dir, exist_ok=True)
        ref_path, ref_mean, chunks, own = reference(scene, out_dir)
        frame = os.path.join(REALSET, scene, a.frame + '.exr')
        rows = [('input', frame, None)]
        if a.oidn:
            path = os.path.join(out_dir, f'oidn_{a.frame}.exr')
            tool = ['--oidn', a.oidn_tool] if a.oidn_tool else []
            text = subprocess.run(['/usr/bin/python3', OIDN, frame, path, '--aux', '--runs', '3'] +
                                  tool, capture_output=True, text=True, check=True).stdout
            ms = re.search(r'median ([0-9.]+) ms', text)
            rows.append(('OIDN', path, float(ms.group(1)) / 1000 if ms else None))
        for spec in a.run:
            name, _, args = spec.partition('=')
            path = os.path.join(out_dir, f'{name}_{a.frame}.exr')
            log = os.path.join(out_dir, f'{name}_{a.frame}.log')
            start = time.monotonic()
            with open(log, 'w') as f:
                subprocess.run([a.mcdenoise, 'denoise', frame, '-o', path] + args.split(),
                               stdout=f, stderr=subprocess.STDOUT, check=True)
            rows.append((name, path, time.monotonic() - start))
        print(f'\n### {scene} ({a.frame}; reference: {chunks} chunks, own relMSE ~{own:.2g})\n')
        print('| | relMSE | PSNR | SSIM | brightness | time (s) |')
        print('|---|---|---|---|---|---|')
        for name, path, seconds in rows:
            r, p, s, b = compare(a.mcdenoise, path, ref_path, ref_mean)
            logs.setdefault(name, []).append(r)
            t = f'{seconds:.2f}' if seconds is not None else ''
            print(f'| {name} | {r:.3g} | {p:.2f} | {s:.4f} | {b:.3f} | {t} |')
        sys.stdout.flush()
    print('\n| geometric mean relMSE | ' + ' | '.join(
        f'{n} {math.exp(sum(map(math.log, v)) / len(v)):.3g}' for n, v in logs.items()) + ' |')


if __name__ == '__main__':
    main()
