#!/usr/bin/python3
"""Make docs/images/cornell-before-after.png from the previews scripts/demo.sh writes: the
noisy frame, auto's output and the reference side by side, each labelled. Needs Debian's
python3-openimageio. Usage, from the repository root after scripts/demo.sh:

    /usr/bin/python3 docs/images/make_before_after.py [out/demo] [docs/images/cornell-before-after.png]
"""
import sys

import OpenImageIO as oiio
from OpenImageIO import ImageBuf, ImageBufAlgo, ImageSpec, ROI

FONT = "/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf"
PANELS = [("cornell.png", "noisy, 8 spp"), ("cornell-auto.png", "mcdenoise (auto)"),
          ("cornell-reference.png", "reference, 256 spp")]
GAP, LABEL = 4, 22


def Main():
    demo = sys.argv[1] if len(sys.argv) > 1 else "out/demo"
    out = sys.argv[2] if len(sys.argv) > 2 else "docs/images/cornell-before-after.png"
    images = [ImageBuf(f"{demo}/{name}") for name, _ in PANELS]
    for image in images:
        if image.has_error:
            sys.exit(f"make_before_after: {image.geterror()}")
    w, h = images[0].spec().width, images[0].spec().height
    strip = ImageBuf(ImageSpec(len(images) * w + (len(images) - 1) * GAP, h + LABEL, 3,
                               oiio.UINT8))
    ImageBufAlgo.fill(strip, (1.0, 1.0, 1.0))
    for i, (image, (_, label)) in enumerate(zip(images, PANELS)):
        x = i * (w + GAP)
        rgb = ImageBufAlgo.channels(image, (0, 1, 2))
        ImageBufAlgo.paste(strip, x, LABEL, 0, 0, rgb)
        ImageBufAlgo.render_text(strip, x + 6, LABEL - 6, label, 15, FONT, (0.0, 0.0, 0.0))
    strip.specmod().attribute("png:compressionLevel", 9)
    if not strip.write(out):
        sys.exit(f"make_before_after: {strip.geterror()}")
    print(f"make_before_after: {out} ({strip.spec().width}x{strip.spec().height})")


if __name__ == "__main__":
    Main()
