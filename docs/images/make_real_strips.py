#!/usr/bin/python3
"""Make the real-scene strips of docs/results.md from the previews `mcdenoise bench real`
writes: for a few scenes and frames, the input, some outputs and the reference side by side,
each labelled. Needs Debian's python3-openimageio. Usage, from the repository root after
`mcdenoise bench real`:

    /usr/bin/python3 docs/images/make_real_strips.py [out/bench-real] [docs/images]
"""
import sys

import OpenImageIO as oiio
from OpenImageIO import ImageBuf, ImageBufAlgo, ImageSpec

FONT = "/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf"
# Per strip: scene, frame, the methods shown between the input and the reference.
STRIPS = [("sunlit_room", "accumulated", ["pivot", "rhf", "auto", "oidn"]),
          ("glossy_lights", "plain", ["pivot", "auto", "oidn"]),
          ("glossy_lights", "accumulated", ["rhf", "nfor", "auto", "oidn"]),
          ("product_transparent", "accumulated", ["bayes", "auto", "oidn"]),
          ("motion_blur", "plain", ["pivot", "auto", "oidn"])]
GAP, LABEL = 4, 22


def Strip(bench, scene, frame, methods, out):
    panels = [(f"{scene}-{frame}-input.png", f"input ({frame})")]
    panels += [(f"{scene}-{frame}-{m}.png", m) for m in methods]
    panels += [(f"{scene}-reference-color.png", "reference")]
    images = [ImageBuf(f"{bench}/{name}") for name, _ in panels]
    for image in images:
        if image.has_error:
            sys.exit(f"make_real_strips: {image.geterror()}")
    w, h = images[0].spec().width, images[0].spec().height
    strip = ImageBuf(ImageSpec(len(images) * w + (len(images) - 1) * GAP, h + LABEL, 3,
                               oiio.UINT8))
    ImageBufAlgo.fill(strip, (1.0, 1.0, 1.0))
    for i, (image, (_, label)) in enumerate(zip(images, panels)):
        x = i * (w + GAP)
        ImageBufAlgo.paste(strip, x, LABEL, 0, 0, ImageBufAlgo.channels(image, (0, 1, 2)))
        ImageBufAlgo.render_text(strip, x + 6, LABEL - 6, label, 15, FONT, (0.0, 0.0, 0.0))
    strip.specmod().attribute("png:compressionLevel", 9)
    if not strip.write(out):
        sys.exit(f"make_real_strips: {strip.geterror()}")
    print(f"make_real_strips: {out} ({strip.spec().width}x{strip.spec().height})")


def Main():
    bench = sys.argv[1] if len(sys.argv) > 1 else "out/bench-real"
    folder = sys.argv[2] if len(sys.argv) > 2 else "docs/images"
    for scene, frame, methods in STRIPS:
        Strip(bench, scene, frame, methods, f"{folder}/real-{scene}-{frame}.png")


if __name__ == "__main__":
    Main()
