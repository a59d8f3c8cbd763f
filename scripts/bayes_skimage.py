#!/usr/bin/env python3
# Usage: /usr/bin/python3 scripts/bayes_skimage.py FRAME.exr OUT.exr split|whole rgb|ycbcr
# Needs python3-skimage and python3-openimageio (Debian); not part of CI.
# scikit-image denoise_wavelet (BayesShrink, soft, db1 = Haar) on an mcdenoise frame:
# whole color, or indirect only + direct (split). Writes EXR for `mcdenoise compare`.
import sys, time
import numpy as np
import OpenImageIO as oiio
from skimage.restoration import denoise_wavelet

def read_layers(path):
    inp = oiio.ImageInput.open(path)
    spec = inp.spec()
    data = inp.read_image(oiio.FLOAT)
    inp.close()
    names = list(spec.channelnames)
    def layer(prefix):
        want = [prefix + c for c in ("R", "G", "B")]
        if not all(w in names for w in want):
            return None
        return np.stack([data[:, :, names.index(w)] for w in want], axis=-1).astype(np.float64)
    return layer(""), layer("direct."), layer("indirect.")

def write(path, img):
    spec = oiio.ImageSpec(img.shape[1], img.shape[0], 3, oiio.FLOAT)
    out = oiio.ImageOutput.create(path)
    out.open(path, spec)
    out.write_image(img.astype(np.float32))
    out.close()

src, dst, mode, ycbcr = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4] == "ycbcr"
color, direct, indirect = read_layers(src)
def den(x):
    return denoise_wavelet(x, method="BayesShrink", mode="soft", wavelet="db1",
                           channel_axis=-1, convert2ycbcr=ycbcr, rescale_sigma=True)
t = time.perf_counter()
out = den(indirect) + direct if mode == "split" else den(color)
print(f"skimage {mode} {'ycbcr' if ycbcr else 'rgb'}: {1e3 * (time.perf_counter() - t):.1f} ms")
write(dst, out)
