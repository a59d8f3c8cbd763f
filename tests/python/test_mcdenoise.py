"""The Python module (python/mcdenoise) over the library in the build tree: shapes and
types in and out, strided and half arrays, layers from files, errors as exceptions per
code, progress and cancellation, and the same bits as the command line."""

import os
import subprocess
import warnings

import numpy as np
import pytest

import mcdenoise

DATA = os.path.join(os.path.dirname(__file__), "..", "data")
GLOSSY = os.path.join(DATA, "cycles_glossy_box_32_16spp.exr")


def noisy(height=24, width=20, channels=3, seed=1):
    rng = np.random.default_rng(seed)
    return rng.lognormal(size=(height, width, channels)).astype(np.float32)


def test_issue_check():
    out = mcdenoise.denoise(np.random.rand(64, 64, 3).astype(np.float32))
    assert out.shape == (64, 64, 3) and out.dtype == np.float32
    assert np.isfinite(out).all()


def test_methods_and_params():
    names = mcdenoise.methods()
    assert names[0] == "auto"
    assert {"awr", "bayes", "pivot", "rhf"} <= set(names)
    params = mcdenoise.method_params("rhf")
    assert "kappa" in params and "non-finite" in params
    assert mcdenoise.version().count(".") == 2


def test_strided_arrays_give_the_contiguous_bits():
    color = noisy()
    expected = mcdenoise.denoise(color, method="bayes")
    rgba = np.concatenate([color, np.ones(color.shape[:2] + (1,), np.float32)], axis=2)
    assert np.array_equal(mcdenoise.denoise(rgba[:, :, :3], method="bayes"), expected)
    planar = np.ascontiguousarray(color.transpose(2, 0, 1)).transpose(1, 2, 0)
    assert not planar.flags.c_contiguous
    assert np.array_equal(mcdenoise.denoise(planar, method="bayes"), expected)
    flipped = np.ascontiguousarray(color[::-1])[::-1]
    assert np.array_equal(mcdenoise.denoise(flipped, method="bayes"), expected)
    # Broadcast arrays (strides of 0) give their copy's bits.
    row = color[:1]
    broadcast = np.broadcast_to(row, color.shape)
    assert broadcast.strides[0] == 0
    assert np.array_equal(mcdenoise.denoise(broadcast, method="bayes"),
                          mcdenoise.denoise(np.ascontiguousarray(broadcast), method="bayes"))
    grey = np.broadcast_to(color[:, :, :1], color.shape)
    assert np.array_equal(mcdenoise.denoise(grey, method="bayes"),
                          mcdenoise.denoise(np.ascontiguousarray(grey), method="bayes"))


def test_alpha_passes_through_and_shapes_are_kept():
    color = noisy()
    alpha = np.random.default_rng(2).random(color.shape[:2] + (1,), np.float32)
    out = mcdenoise.denoise(np.concatenate([color, alpha], axis=2), method="bayes")
    assert out.shape == color.shape[:2] + (4,)
    assert np.array_equal(out[:, :, 3], alpha[:, :, 0])
    gray = mcdenoise.denoise(color[:, :, 0], method="bayes")
    assert gray.shape == color.shape[:2]


def test_alpha_rim_moves_light_only_where_its_alpha_comes_back():
    color = noisy()
    alpha = np.full(color.shape[:2] + (1,), 0.8, np.float32)
    alpha[:, :6] = 0.0  # a transparent background, its rim in column 5
    rgba = np.concatenate([color, alpha], axis=2)
    out = mcdenoise.denoise(rgba, method="bayes")
    kept = mcdenoise.denoise(rgba, method="bayes", alpha_rim=0.0)
    assert np.array_equal(kept[:, :, 3], alpha[:, :, 0])
    # RGBA: the rim takes colour and alpha alike; none is added; farther out nothing moves
    assert (out[:, 5, 3] > 0).all() and (out[:, 5, :3] != color[:, 5]).any()
    assert np.array_equal(out[:, :5, :3], color[:, :5]) and (out[:, :5, 3] == 0).all()
    np.testing.assert_allclose(out.sum(axis=(0, 1)), kept.sum(axis=(0, 1)), rtol=1e-5)
    # 3 channels and an alpha layer: the alpha does not come back, so no light moves
    three = mcdenoise.denoise(color, method="bayes", layers={"alpha": alpha})
    assert three.shape == color.shape
    assert np.array_equal(three, kept[:, :, :3])
    assert np.array_equal(three[:, :6], color[:, :6])


def test_half_in_half_out():
    color16 = noisy().astype(np.float16)
    out16 = mcdenoise.denoise(color16, method="bayes")
    assert out16.dtype == np.float16
    out32 = mcdenoise.denoise(color16.astype(np.float32), method="bayes")
    assert np.array_equal(out16, out32.astype(np.float16))


def test_layers_from_a_file_and_the_command_lines_bits(tmp_path):
    frame = mcdenoise.read_frame(GLOSSY)
    assert frame["color"].shape == (32, 32, 3) and frame["color"].dtype == np.float32
    assert {"albedo", "normal", "depth"} <= set(frame)
    only = mcdenoise.read_frame(GLOSSY, layers=["color"])
    assert np.array_equal(only["color"], frame["color"])
    out = mcdenoise.denoise(frame["color"], method="pivot", layers=frame)
    tool = os.environ.get("MCDENOISE_TOOL")
    if not tool:
        pytest.skip("MCDENOISE_TOOL (the command line) not set")
    written = tmp_path / "pivot.exr"
    subprocess.run([tool, "denoise", GLOSSY, "--method", "pivot", "-o", str(written)],
                   check=True, capture_output=True)
    assert np.array_equal(mcdenoise.read_frame(written)["color"], out)


def test_write_exr_round_trips(tmp_path):
    color, depth = noisy(), noisy(channels=1, seed=3)
    path = tmp_path / "layers.exr"
    mcdenoise.write_exr(path, {"color": color, "depth": depth[:, :, 0]})
    back = mcdenoise.read_frame(path)
    assert np.array_equal(back["color"], color) and np.array_equal(back["depth"], depth)


def test_errors_are_exceptions_per_code(tmp_path):
    color = noisy()
    with pytest.raises(mcdenoise.InvalidArgumentError, match="unknown method 'nope'"):
        mcdenoise.denoise(color, method="nope")
    with pytest.raises(mcdenoise.InvalidArgumentError, match="kappa"):
        mcdenoise.denoise(color, method="rhf", kappa=-1.0)
    with pytest.raises(mcdenoise.InvalidArgumentError, match="4294967298"):
        mcdenoise.denoise(color, method="rhf", knn=2**32 + 2)  # not cut to a C int
    with pytest.raises(ValueError):  # InvalidArgumentError is a ValueError too
        mcdenoise.denoise(color, method="rhf", no_such_parameter=1)
    with pytest.raises(mcdenoise.MissingLayerError,
                       match="--demodulate albedo needs a layer the frame lacks"):
        mcdenoise.denoise(color, method="bayes", demodulate="albedo")
    with pytest.raises(mcdenoise.MissingLayerError, match="histogram"):
        mcdenoise.denoise(color, method="rhf")
    with pytest.raises(mcdenoise.InvalidArgumentError):
        mcdenoise.denoise(color, albedo=np.ones((3, 3, 3), np.float32))
    bad = color.copy()
    bad[4, 5, 1] = np.nan
    with pytest.raises(mcdenoise.NonFiniteInputError, match=r"pixel \(5, 4\), channel 1"):
        mcdenoise.denoise(bad, method="bayes")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = mcdenoise.denoise(bad, method="bayes", non_finite="zero")
    assert np.isfinite(out).all()
    assert any(issubclass(w.category, mcdenoise.LibraryWarning) for w in caught)
    with pytest.raises(mcdenoise.InvalidArgumentError, match="method"):
        mcdenoise.denoise(color, method=None)
    with pytest.raises(mcdenoise.InvalidArgumentError, match="layer name"):
        mcdenoise.denoise(color, layers={1: color})
    with pytest.raises(mcdenoise.InvalidArgumentError, match="complex"):
        mcdenoise.denoise(color.astype(np.complex64))
    with pytest.raises(mcdenoise.InvalidArgumentError, match="device"):
        mcdenoise.denoise(color, device=3.5)
    assert mcdenoise.denoise(color, method="bayes", device=0).shape == color.shape
    with pytest.raises(mcdenoise.MissingLayerError, match="has no layer 'nope'"):
        mcdenoise.read_frame(GLOSSY, layers=["color", "nope"])
    # A wildcard asks for what there is; names come in any sequence.
    assert "color" in mcdenoise.read_frame(GLOSSY, layers=["color", "partial*"])
    assert "color" in mcdenoise.read_frame(GLOSSY, layers=np.array(["color"]))
    with pytest.raises(mcdenoise.IoError) as missing:
        mcdenoise.read_frame(tmp_path / "absent.exr")
    assert isinstance(missing.value, OSError) and "absent.exr" in str(missing.value)


def test_progress_and_cancellation():
    color = noisy()
    calls = []
    mcdenoise.denoise(color, method="awr", variance=noisy(seed=4), awr_spins=2,
                      progress=lambda stage, done, total: calls.append(stage))
    assert calls  # polled at least before each submission
    with pytest.raises(mcdenoise.CancelledError):
        mcdenoise.denoise(color, method="bayes", progress=lambda *a: False)

    def failing(*args):
        raise KeyError("from the callback")
    with pytest.raises(KeyError, match="from the callback"):
        mcdenoise.denoise(color, method="bayes", progress=failing)
    # The device runs normally after a cancelled run.
    assert mcdenoise.denoise(color, method="bayes").shape == color.shape
