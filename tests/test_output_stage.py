"""The output stage's two twins (renderer/gpu/output.py with glsl/output/output.comp, and
reference/output/): the contract both follow (docs/conventions.md, "Output"), and GPU against
twin bit for bit on frames made to hold every case (NaN, infinities, negatives, above 1,
each code's edges).

The rules themselves (quantisation, dithering, float encoding) have their own files:
test_output_quantise.py, test_output_dither.py, test_output_transfer.py.
"""

import numpy as np
import pytest

import reference.output
from renderer.core.output_settings import Halftone, OutputSettings
from output_cases import TRANSFERS, linear_frame


@pytest.mark.parametrize("kind", ("egl", "osmesa"))
@pytest.mark.parametrize("transfer", TRANSFERS, ids=str)
def test_undithered_codes_on_the_gpu_are_the_twins(output_passes, kind, transfer):
    frame = linear_frame()
    for bits in (1, 8, 16):
        settings = OutputSettings(transfer=transfer, bits=bits, format="png16")
        gpu = output_passes[kind].apply(frame, settings)
        assert gpu.dtype == np.uint16 and gpu.shape == frame.shape
        np.testing.assert_array_equal(gpu, reference.output.apply(frame, settings),
                                      err_msg=f"{transfer} at {bits} bits")


@pytest.mark.parametrize("kind", ("egl", "osmesa"))
def test_the_pass_makes_its_gl_objects_once(output_passes, kind, monkeypatch):
    """Programs, images and tables are kept: applying settings and a size seen before makes
    no GL object at all (counted at moderngl's constructors)."""
    import moderngl
    stage = output_passes[kind]
    frame = linear_frame(24, 16)
    runs = [OutputSettings(transfer=TRANSFERS[1], bits=2, dither="blue-noise"),
            OutputSettings(bits=4, dither="bayer8"), OutputSettings(transfer=TRANSFERS[2], format="exr"),
            OutputSettings(bits=1, dither="jarvis-judice-ninke"), OutputSettings(halftone=Halftone(6, 15))]
    for settings in runs:
        stage.apply(frame, settings)
    made = []
    for name in ("texture", "buffer", "compute_shader"):
        constructor = getattr(moderngl.Context, name)
        monkeypatch.setattr(moderngl.Context, name,
                            lambda self, *a, _c=constructor, _n=name, **k: made.append(_n) or _c(self, *a, **k))
    held = [id(obj) for obj in stage.gl_objects()]
    for settings in runs:
        stage.apply(frame, settings)
    assert made == [] and [id(obj) for obj in stage.gl_objects()] == held
    stage.apply(linear_frame(16, 8), runs[0])                      # a new size: two images
    assert made == ["texture", "texture"]


def test_a_program_holds_only_what_its_settings_use(output_passes):
    """Each method is a define: the driver compiles the rest out, and what a program reads
    shows which (a uniform nothing reads is not active)."""
    stage = output_passes["egl"]
    programs = {
        "none": OutputSettings(),
        "bayer4": OutputSettings(dither="bayer4"),
        "blue-noise": OutputSettings(dither="blue-noise"),
        "srgb float": OutputSettings(transfer=TRANSFERS[1], format="npy"),
        "linear float": OutputSettings(format="npy"),
    }
    programs |= {"half-tone": OutputSettings(halftone=Halftone(6)),
                 "floyd-steinberg": OutputSettings(dither="floyd-steinberg")}
    active = {name: {u for u in ("u_decision_points", "u_code_values", "u_blue_noise_size",
                                 "u_exponent", "u_bits", "u_screen", "u_shares")
                     if stage.program(s).get(u, None) is not None}
              for name, s in programs.items()}
    assert active == {"none": {"u_decision_points", "u_bits"},
                      "bayer4": {"u_code_values", "u_bits"},
                      "blue-noise": {"u_code_values", "u_blue_noise_size", "u_bits"},
                      "srgb float": {"u_exponent"},
                      "linear float": set(),
                      "half-tone": {"u_screen", "u_bits"},
                      "floyd-steinberg": {"u_code_values", "u_bits", "u_shares"}}
    assert stage.program(OutputSettings(dither="bayer4")) is stage.program(OutputSettings(dither="bayer4"))


def test_output_stages_and_their_twins_name_each_other():
    """Line 1 of each GLSL file of the stage names its NumPy twin, whose line 1 names a GLSL
    file of the stage back (two GLSL files may share a twin); every twin has a GLSL file."""
    from renderer.core.resources import glsl_dir
    root = glsl_dir().parent
    shaders = sorted([*(glsl_dir() / "output").glob("*.glsl"), *(glsl_dir() / "output").glob("*.comp")])
    twins = set()
    for shader in shaders:
        lines = shader.read_text().splitlines()
        assert lines[0].startswith("// Twin: reference/output/"), shader.name
        twin = root / lines[0].removeprefix("// Twin: ")
        back = twin.read_text().splitlines()[0]
        assert back.startswith('"""# Twin: glsl/output/') and (root / back[len('"""# Twin: '):]).is_file()
        if shader.suffix == ".comp":
            assert lines[1] == "#version 430 core", shader.name
        twins.add(twin)
    assert twins == set((root / "reference" / "output").glob("*.py"))
