#!/usr/bin/python3
"""Count halo pixels on a real Cycles frame (issue 29; docs/methods/pivot.md, eleventh round).

usage: /usr/bin/python3 scripts/realset_halo.py SCENE plain|acc [OUTPUT.exr ...]

The reference is the mean of ~/.cache/mcdenoise/realset/SCENE/ref/chunk*.exr. A pixel is on
the shadow side of an edge when the reference's 3x3 mean luminance is above 0.01 and under
half the largest 3x3 mean within 4 pixels. Of those, a halo pixel has an image's 3x3 mean
over 1.15 of the reference's; a dark one under 1 / 1.15 of it. Prints both counts for the
input frame, for the reference's own noise (its first chunk against the others' mean) and
for each output given.
"""
import glob, os, sys
import numpy as np
import OpenImageIO as oiio

REALSET = os.path.expanduser('~/.cache/mcdenoise/realset')


def read_rgb(path):
    inp = oiio.ImageInput.open(path)
    spec = inp.spec()
    pixels = np.asarray(inp.read_image(0, 0, 0, spec.nchannels, 'float'))
    inp.close()
    pixels = pixels.reshape(spec.height, spec.width, spec.nchannels)
    names = list(spec.channelnames)
    for prefix in ('', 'ViewLayer.Combined.'):
        if prefix + 'R' in names:
            return np.stack([pixels[..., names.index(prefix + c)] for c in 'RGB'], -1)
    sys.exit('%s: no R, G, B channels' % path)


def luminance(rgb):
    return rgb[..., 0] * 0.2126 + rgb[..., 1] * 0.7152 + rgb[..., 2] * 0.0722


def window(image, radius, combine):
    """combine over the (2 radius + 1)^2 window of each pixel, edges repeated."""
    padded = np.pad(image, radius, mode='edge')
    h, w = image.shape
    out = None
    for dy in range(2 * radius + 1):
        for dx in range(2 * radius + 1):
            part = padded[dy:dy + h, dx:dx + w]
            out = part.copy() if out is None else combine(out, part)
    return out


def mean3(rgb):
    return window(luminance(rgb), 1, np.add) / 9


def main():
    if len(sys.argv) < 3 or sys.argv[2] not in ('plain', 'acc'):
        sys.exit(__doc__)
    scene, frame = sys.argv[1], sys.argv[2]
    chunks = [read_rgb(p) for p in sorted(glob.glob(os.path.join(REALSET, scene, 'ref', 'chunk*.exr')))]
    if not chunks:
        sys.exit('%s: no reference chunks' % scene)
    ref = mean3(np.mean(chunks, 0))
    shadow = (ref < 0.5 * window(ref, 4, np.maximum)) & (ref > 0.01)

    def counts(image, against):
        return int((shadow & (image > 1.15 * against)).sum()), int((shadow & (image < against / 1.15)).sum())

    print('%s %s: %d shadow-side pixels; halo (over 1.15 of the reference), dark (under 1/1.15)' %
          (scene, frame, shadow.sum()))
    rows = [('input', counts(mean3(read_rgb(os.path.join(REALSET, scene, frame + '.exr'))), ref))]
    if len(chunks) > 1:
        rows.append(('reference own', counts(mean3(chunks[0]), mean3(np.mean(chunks[1:], 0)))))
    rows += [(path, counts(mean3(read_rgb(path)), ref)) for path in sys.argv[3:]]
    for name, (halo, dark) in rows:
        print('  %-40s %6d %6d' % (name, halo, dark))


if __name__ == '__main__':
    main()
