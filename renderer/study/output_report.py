"""The output knob of `renderer report` (issue 18): what each way of putting a frame on an
N-bit display costs and how far the light it shows is from the light computed.

    setting            what runs                                       backends
    METHOD N-bit       the output stage (renderer/gpu/output.py,        GPU and reference
                       reference/output/) with dither METHOD at N
                       bits, sRGB transfer
    halftone 1-bit     the CMYK half-tone (HALFTONE's cell and angle)   GPU and reference
    code-value METHOD  METHOD's thresholds applied to the ENCODED       reference (a study,
    N-bit              values (renderer/study/code_value_dither.py):    not a stage)
                       the mistake the stage avoids

Each scene is drawn once, as authored, one sample at each pixel's centre, by the GPU; its
linear colour is the stage's input for every setting and backend, and the undithered linear
image (L clamped to [0, 1]) is what each output is measured against. The light an output
shows is each code's linear value (quantise.code_values). Measured, all on CIE luminance Y
(reference/output/colour.py, the Rec. 709 weights):
- the aligned 8 x 8 blocks' mean luminance error, shown - computed: its mean |e|, 95th
  percentile, max |e| and the signed bias (the mean over blocks). A 1-bit block can only show
  65 means a channel (steps of 1/64 = 4/255), so no method keeps every block within 0.5/255 at
  1 bit; the bias is what dithering in linear light keeps near 0 and code-value dithering does
  not (docs/conventions.md, "Output");
- PSNR (peak 1) of the two luminance images after a Gaussian low-pass standing for the eye:
  ꟻLIP's own achromatic contrast-sensitivity filter, exp(-pi^2 x^2 / b) with b = 0.0047 deg^2
  (Andersson et al. 2020; FLIP.h's GaussianConstants), at ꟻLIP's default viewing condition, a
  0.7 m wide 3840-pixel display seen from 0.7 m (67.0 pixels per degree): a Gaussian of
  sigma = sqrt(b / 2 pi^2) degrees = EYE_SIGMA pixels (1.03). The eye averages away what is
  finer than that; what is coarser (Bayer 8's 8-pixel tile, error diffusion's worms) it sees;
- ꟻLIP (renderer/checks/perceptual.py) between the sRGB-encoded computed and shown images, in
  float, at the same 67 pixels per degree;
- milliseconds per frame of the stage alone (upload, dispatch, read-back on the GPU), the
  median of the sweep's runs after one untimed run.
"""

from __future__ import annotations

import math

import numpy as np

from renderer.core.output_settings import ERROR_DIFFUSION, Halftone, ORDERED, OutputSettings, Transfer
from renderer.core.quantise import code_values, encode
from reference.output.colour import luminance

KNOB = "output"
METHODS = ("none", *ORDERED, "blue-noise", *ERROR_DIFFUSION)
BITS = (1, 2, 4, 8)
HALFTONE = Halftone(4.0, 0.0)          # 4-pixel cells, the inks at their classic angles
CODE_VALUE = ("blue-noise",)           # dithered in the encoded domain, for the bias row
TRANSFER = Transfer("srgb")
BLOCK = 8
FLIP_PPD = 0.7 * 3840 / 0.7 * math.pi / 180        # ꟻLIP's default viewing condition
FLIP_ACHROMATIC_B = 0.0047                          # deg^2, ꟻLIP's luminance filter
EYE_SIGMA = math.sqrt(FLIP_ACHROMATIC_B / (2 * math.pi ** 2)) * FLIP_PPD   # pixels: 1.03


def output_variants(methods, bits, halftone: bool, code_value) -> list[tuple[str, tuple, tuple]]:
    """(setting, variant, backends) of each output setting; variant = ("output", kind,
    method, bits) with kind "stage" or "code-value"."""
    both, reference = ("gpu", "reference"), ("reference",)
    found = [(f"{m} {b}-bit", ("output", "stage", m, b), both) for m in methods for b in bits]
    if halftone:
        found.append(("halftone 1-bit", ("output", "stage", "halftone", 1), both))
    found += [(f"code-value {m} {b}-bit", ("output", "code-value", m, b), reference)
              for m in code_value for b in bits]
    return found


def output_settings(variant: tuple) -> OutputSettings:
    _, _, method, bits = variant
    if method == "halftone":
        return OutputSettings(TRANSFER, 1, halftone=HALFTONE, format="png8")
    return OutputSettings(TRANSFER, bits, dither=method, format="png8")


def gaussian_blur(image: np.ndarray, sigma: float) -> np.ndarray:
    """(H, W) float64 blurred by a normalised Gaussian of `sigma` pixels, 3 sigma each side,
    separably, the edges mirrored (each border pixel's neighbours are the image's own)."""
    radius = int(math.ceil(3 * sigma))
    taps = np.exp(-np.arange(-radius, radius + 1) ** 2 / (2 * sigma ** 2))
    taps /= taps.sum()
    for axis in (0, 1):
        padded = np.pad(image, [(radius, radius) if a == axis else (0, 0) for a in (0, 1)],
                        mode="symmetric")
        length = image.shape[axis]
        image = sum(w * np.take(padded, range(i, i + length), axis=axis) for i, w in enumerate(taps))
    return image


def output_errors(linear: np.ndarray, codes: np.ndarray, settings: OutputSettings) -> dict:
    """The columns of one output row (module docstring): `codes` (H, W, 4) shown against the
    linear frame (H, W, 4) it was made from."""
    from renderer.checks.perceptual import flip_mean
    computed = np.clip(np.nan_to_num(linear[..., :3].astype(np.float64)), 0.0, 1.0)
    shown = code_values(settings.transfer, settings.code_bits)[codes[..., :3]].astype(np.float64)
    y_computed, y_shown = luminance(computed), luminance(shown)
    rows, columns = (n // BLOCK * BLOCK for n in y_shown.shape)
    blocks = (y_shown - y_computed)[:rows, :columns].reshape(
        rows // BLOCK, BLOCK, columns // BLOCK, BLOCK).mean(axis=(1, 3))
    mse = float(np.mean((gaussian_blur(y_shown, EYE_SIGMA) - gaussian_blur(y_computed, EYE_SIGMA)) ** 2))
    return {"block_mean_abs": float(np.abs(blocks).mean()),
            "block_p95_abs": float(np.percentile(np.abs(blocks), 95)),
            "block_max_abs": float(np.abs(blocks).max()),
            "block_bias": float(blocks.mean()),
            "lowpass_psnr": 10 * math.log10(1 / mse) if mse > 0 else math.inf,
            "flip_mean": flip_mean(encode(computed, TRANSFER), encode(shown, TRANSFER), FLIP_PPD)}


class OutputRun:
    """One scene's output settings: its linear frame, drawn once by `gpu` (a GpuRenderer),
    and the GPU stage in the same context, made once."""

    def __init__(self, gpu):
        from renderer.gpu.output import OutputPass
        self.linear = gpu.render(linear=True, depth=False).linear.copy()
        self.stage = OutputPass(gpu.ctx)

    def codes(self, variant: tuple, backend: str) -> np.ndarray:
        settings = output_settings(variant)
        if variant[1] == "code-value":
            from renderer.study.code_value_dither import code_value_dither
            return code_value_dither(self.linear, settings)
        if backend == "gpu":
            return self.stage.apply(self.linear, settings)
        import reference.output
        return reference.output.apply(self.linear, settings)

    def errors(self, variant: tuple, codes: np.ndarray) -> dict:
        _, _, method, bits = variant
        return {"method": method if variant[1] == "stage" else f"code-value {method}",
                "bits": bits, **output_errors(self.linear, codes, output_settings(variant))}

    def release(self) -> None:
        self.stage.release()


# ------------------------------------------------------------------------------- report.md

def method_bullet() -> str:
    return (f"- **output** (issue 18): each scene drawn once as authored, one sample per pixel, "
            f"by the GPU; its linear colour through the output stage at each method and bit "
            f"depth, sRGB transfer, on both backends (the same codes: tests/test_output_*.py), "
            f"and measured against the undithered linear image (L clamped to [0, 1]) in CIE "
            f"luminance: the 8x8 blocks' mean error (mean |e|, 95th percentile, max, and the "
            f"signed bias over blocks, in levels of 1/255), PSNR after the eye's low-pass "
            f"(ꟻLIP's achromatic filter at its 67 pixels per degree: a Gaussian of sigma "
            f"{EYE_SIGMA:.2f} pixels), ꟻLIP on the sRGB images, and the stage's own time per "
            f"frame. The half-tone prints CMYK ink at 1 bit ({HALFTONE.cell:g}-pixel cells); "
            f"`code-value` rows dither the ENCODED values instead of the light (reference "
            f"only; renderer/study/output_report.py has the details).")


def _by_setting(rows: list[dict]) -> dict:
    """(method, bits) -> {"gpu": [rows], "reference": [rows]} over the scenes."""
    table: dict = {}
    for row in rows:
        table.setdefault((row["method"], row["bits"]), {}).setdefault(row["backend"], []).append(row)
    return table


def _mean(rows: list[dict], column: str) -> float:
    return float(np.mean([r[column] for r in rows]))


def _measured(cells: dict) -> list[dict]:
    """The rows whose errors a setting's figures come from: the GPU's where it ran (both
    backends give the same codes), else the reference's."""
    return cells.get("gpu") or cells["reference"]


def ranking(rows: list[dict], bits: int = 1) -> list[tuple]:
    """[(method, figures)] at `bits`, best first by the low-pass PSNR (mean over scenes)."""
    found = []
    for (method, row_bits), cells in _by_setting(rows).items():
        if row_bits == bits:
            measured = _measured(cells)
            figures = {c: _mean(measured, c) for c in (
                "lowpass_psnr", "flip_mean", "block_mean_abs", "block_p95_abs", "block_max_abs",
                "block_bias")}
            figures |= {f"{b}_ms": _mean(cells[b], "median_ms") if b in cells else None
                        for b in ("gpu", "reference")}
            found.append((method, figures))
    found.sort(key=lambda item: -item[1]["lowpass_psnr"])
    flip_order = sorted(found, key=lambda item: item[1]["flip_mean"])
    for method, figures in found:
        figures["flip_rank"] = 1 + [m for m, _ in flip_order].index(method)
    return found


def _levels(value: float) -> str:
    return f"{value * 255:+.2f}" if value < 0 or value > 0 else "0"


def _ms(value) -> str:
    return "" if value is None else f"{value:.3g}"


def ranking_table(rows: list[dict], bits: int = 1) -> list[str]:
    """The ranking at `bits` as markdown lines (docs/colour-and-output.md quotes it)."""
    lines = ["| rank | method | low-pass PSNR (dB) | ꟻLIP (rank) | block mean \\|e\\| | p95 | max "
             "| bias | GPU ms | reference ms |",
             "| ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for rank, (method, f) in enumerate(ranking(rows, bits), start=1):
        lines.append(f"| {rank} | {method} | {f['lowpass_psnr']:.2f} | {f['flip_mean']:.3f} "
                     f"({f['flip_rank']}) | {f['block_mean_abs'] * 255:.2f} | "
                     f"{f['block_p95_abs'] * 255:.2f} | {f['block_max_abs'] * 255:.2f} | "
                     f"{_levels(f['block_bias'])} | {_ms(f['gpu_ms'])} | {_ms(f['reference_ms'])} |")
    return lines


def output_sections(rows: list[dict]) -> list[str]:
    """report.md's section on the output knob (module docstring), empty without its rows."""
    rows = [r for r in rows if r["knob"] == KNOB]
    if not rows:
        return []
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    table = _by_setting(rows)
    bits = sorted({b for _, b in table})
    methods = list(dict.fromkeys(m for m, _ in table))
    lines = ["", "## Output: quantisation, dithering and half-toning", "",
             f"Means over {len(scenes)} scene(s) ({', '.join(scenes)}). Block errors are in levels "
             "of 1/255 of luminance (8x8 blocks, shown minus computed); the low-pass PSNR is of "
             f"luminance after a Gaussian of sigma {EYE_SIGMA:.2f} pixels, the eye's at 67 pixels "
             "per degree (renderer/study/output_report.py); times are the stage's alone per frame.",
             "", "### Ranking at 1 bit per channel (by low-pass PSNR; ꟻLIP's own order in brackets)",
             "", *ranking_table(rows, 1), "",
             "A 1-bit 8x8 block shows one of 65 means per channel (steps of 1/64, 4/255), so no "
             "method holds every block within 0.5/255 at 1 bit: the distribution above (mean, 95th "
             "percentile and max of |e|) is what a method does block by block, the bias (the mean "
             "signed block error) whether it keeps the light. Dithering in linear light keeps the "
             "bias small (a Bayer pattern shows a flat area at the nearest of its n^2 + 1 levels, "
             "within 1/(2 n^2)); `none` rounds in the encoded domain and `code-value` dithers "
             "there, and both brighten: the sRGB curve puts the encoded middle above the light's.",
             "", "### Every bit depth: low-pass PSNR (dB) and bias (levels of 1/255)", "",
             "| method | " + " | ".join(f"{b}-bit PSNR | {b}-bit bias" for b in bits) + " |",
             "| --- | " + " | ".join("---: | ---:" for _ in bits) + " |"]
    for method in methods:
        cells = []
        for b in bits:
            measured = _measured(table[(method, b)]) if (method, b) in table else None
            cells += ([f"{_mean(measured, 'lowpass_psnr'):.2f}", _levels(_mean(measured, "block_bias"))]
                      if measured else ["", ""])
        lines.append(f"| {method} | " + " | ".join(cells) + " |")
    return lines


def output_plot_png(rows: list[dict], title: str) -> bytes:
    """PNG bytes: against bits per channel, a line per method: the low-pass PSNR, the blocks'
    mean |e| (log) and the GPU's (solid) and reference's (dashed) ms per frame (log)."""
    import io

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    figure = Figure(figsize=(13.0, 4.4), dpi=100)
    FigureCanvasAgg(figure)
    panels = figure.subplots(1, 3, gridspec_kw={"left": 0.05, "right": 0.85, "wspace": 0.28,
                                                "bottom": 0.13, "top": 0.88})
    table = _by_setting(rows)
    for index, method in enumerate(dict.fromkeys(m for m, _ in table)):
        colour = f"C{index % 10}"
        keys = sorted(k for k in table if k[0] == method)
        bits = [b for _, b in keys]
        measured = [_measured(table[k])[0] for k in keys]
        marker = "o" if len(bits) > 1 else "D"
        panels[0].plot(bits, [r["lowpass_psnr"] for r in measured], marker=marker, color=colour,
                       label=method)
        panels[1].plot(bits, [max(r["block_mean_abs"] * 255, 1e-3) for r in measured],
                       marker=marker, color=colour)
        for backend, line in (("gpu", "-"), ("reference", "--")):
            timed = [(b, table[k][backend][0]["median_ms"]) for b, k in zip(bits, keys)
                     if backend in table[k]]
            if timed:
                panels[2].plot(*zip(*timed), marker=marker, linestyle=line, color=colour)
    for axes, label in zip(panels, ("PSNR after the eye's low-pass (dB)",
                                    "8x8 blocks' mean |luminance error| (1/255)",
                                    "ms per frame (GPU solid, reference dashed)")):
        axes.set_xscale("log", base=2)
        axes.set_xticks([1, 2, 4, 8], ["1", "2", "4", "8"])
        axes.set_xlabel("bits per channel")
        axes.set_ylabel(label)
        axes.grid(True, which="both", linewidth=0.3)
    panels[1].set_yscale("log")
    panels[2].set_yscale("log")
    figure.legend(*panels[0].get_legend_handles_labels(), loc="center left",
                  bbox_to_anchor=(0.86, 0.5), fontsize=7)
    figure.suptitle(title, fontsize=10)
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", metadata={"Software": None})
    return buffer.getvalue()
