#!/usr/bin/python3
# Letter crops and brightness for the pivot note (issue #7): the paper warns that the image
# filter overestimates the brightness of the texture letters. Usage:
#   pivot_letters.py OUT.png REF.exr IMAGE.exr...
# The letters are the reference's pixels of the letter band (rows 50-85) brighter than the
# band's median: prints each image's mean there over the reference's, and writes the band of
# every image side by side (sRGB, 3x) to OUT.png. Needs python3-openimageio and numpy.
import sys
import numpy as np
import OpenImageIO as oiio


def Read(path):
    inp = oiio.ImageInput.open(path)
    if not inp:
        sys.exit(f"cannot open {path}")
    names = list(inp.spec().channelnames)
    data = inp.read_image(oiio.FLOAT)
    inp.close()
    rgb = ["R", "G", "B"] if "R" in names else ["color.R", "color.G", "color.B"]
    return data[:, :, [names.index(c) for c in rgb]].astype(np.float64)


out, refPath, paths = sys.argv[1], sys.argv[2], sys.argv[3:]
ref = Read(refPath)
band = (slice(50, 86), slice(8, 120))
refBand = ref[band].mean(axis=2)
letters = refBand > np.median(refBand)
tiles = []
for path in [refPath] + paths:
    image = Read(path)
    crop = image[band]
    ratio = crop.mean(axis=2)[letters].mean() / refBand[letters].mean()
    if path != refPath:
        print(f"{path}: letters {ratio:.3f} of the reference's brightness")
    srgb = np.clip(crop, 0, 1) ** (1 / 2.2)
    tiles += [np.repeat(np.repeat(srgb, 3, axis=0), 3, axis=1), np.ones((crop.shape[0] * 3, 4, 3))]
pixels = (np.concatenate(tiles[:-1], axis=1) * 255 + 0.5).astype(np.uint8)
png = oiio.ImageOutput.create(out)
png.open(out, oiio.ImageSpec(pixels.shape[1], pixels.shape[0], 3, oiio.UINT8))
png.write_image(pixels)
png.close()
