"""The output stage on the GPU (glsl/output/output.comp; twin: reference/output/): a frame's
linear colour to N-bit codes or to encoded float colour, by a compute shader (GL 4.3).

    stage = OutputPass(ctx)                        # once per context
    codes = stage.apply(frame.linear, settings)    # (H, W, 4) uint16, or float32 for exr/npy
    stage.last_milliseconds                        # upload, dispatch and read-back of that call

The contract (both twins; docs/conventions.md, "Output"): `linear` is (H, W, 4) float32 with
row 0 at the top. It is uploaded as it is (array row r is texel row r) and read back as it is,
so the shader's y is the image row from the top, the dither patterns' y. Quantised formats
give codes in [0, 2^N - 1], N = settings.code_bits; float formats give encode(L) per RGB
channel and alpha as it is.

GL objects are made on first use and kept: a program per set of defines (output_defines(settings):
a program holds only the method it runs), the input and output images per size and kind,
the quantisation tables per (transfer, bits) (renderer/core/quantise.py; one float texture,
`table_texture`), the blue-noise ranks once (an SSBO), error diffusion's error image per size
and its shares per kernel (a float texture), a half-tone's threshold arrays per cell and
turns of its screens on the pixel grid (a float texture). A second apply() with settings and
a size seen before makes no GL object. Error diffusion runs its own program in wavefronts
(`_diffuse`).

Why the tables are a texture and not an SSBO: on llvmpipe (Mesa 22.3.6, EGL and OSMesa) the
read of l_c0 that follows quantise.glsl's search loops, from an SSBO, read the wrong entry in
34 of 1440 pixels (0.0, or with one invocation per work group the entry after it) though the
count it used was right: a driver fault with SSBO loads after such loops (a plain loop with
an SSBO read in its condition did not show it). The same search reading a texture is exact
on every test, and texelFetch gathers about 2.2 times faster (measured: a 640 x 480 binary
search of 8 steps per channel, 84 ms from an SSBO, 38 ms from a texture).
"""

from __future__ import annotations

import time

import moderngl
import numpy as np

from renderer.core.blue_noise import blue_noise_ranks
from renderer.core.error_kernels import KERNELS, pull_taps, sender_weights, wavefronts
from renderer.core.halftone_screen import grid_screens, grid_turns, screen_basis
from renderer.core.output_settings import ERROR_DIFFUSION, OutputSettings, Transfer
from renderer.core.quantise import (SRGB_A, SRGB_EXPONENT, SRGB_LINEAR_LIMIT, SRGB_SLOPE,
                                    code_values, decision_points)
from renderer.gpu.context import activate
from renderer.gpu.defines import output_defines
from renderer.gpu.shaders import compute_program

GROUP_SIZE = 8                       # output.comp's local_size_x and _y
WAVEFRONT_GROUP = 64                 # error_diffusion.comp's local_size_x
MAX_TAPS = 12                        # error_diffusion.comp's tap arrays (Jarvis-Judice-Ninke's)
# Every program of the pass is compiled with them as #defines: the GLSL holds no copy.
PASS_CONSTANTS = {"GROUP_SIZE": GROUP_SIZE, "WAVEFRONT_GROUP": WAVEFRONT_GROUP, "MAX_TAPS": MAX_TAPS}
LINEAR = Transfer("linear")
# Bindings, as the GLSL declares them: images 0 (input), 1 (output) and 2 (error diffusion's
# errors), texture units 0 (the tables), 1 (error diffusion's shares) and 2 (the half-tone's
# threshold arrays), SSBO 1 (blue-noise ranks).
INPUT_IMAGE, OUTPUT_IMAGE, ERROR_IMAGE = 0, 1, 2
TABLES_UNIT, SHARES_UNIT, GRID_THRESHOLDS_UNIT, BLUE_NOISE_BUFFER = 0, 1, 2, 1
TABLE_ROW_BITS = 12                  # the tables' texture is 2^12 entries wide


def table_layout(transfer: Transfer, bits: int) -> tuple[np.ndarray, dict[str, int]]:
    """The quantisation tables of (transfer, bits), one after the other, and the uniforms
    naming where each starts (glsl/output/quantise.glsl): the decision points of the
    transfer, those of the linear transfer (alpha), the codes' linear values."""
    tables = (decision_points(transfer, bits), decision_points(LINEAR, bits),
              code_values(transfer, bits))
    offsets = np.cumsum([0] + [len(t) for t in tables[:-1]])
    names = ("u_decision_points", "u_alpha_points", "u_code_values")
    return np.concatenate(tables), dict(zip(names, map(int, offsets)))


def table_texture(ctx: moderngl.Context, transfer: Transfer, bits: int):
    """(texture, uniforms): table_layout's entries in a float texture 2^TABLE_ROW_BITS wide,
    entry i at texel (i mod width, i div width), and the uniforms that find them."""
    data, offsets = table_layout(transfer, bits)
    width = 1 << TABLE_ROW_BITS
    texels = np.zeros(-(-data.size // width) * width, np.float32)
    texels[:data.size] = data
    texture = ctx.texture((width, texels.size // width), 1, texels.tobytes(), dtype="f4")
    return texture, {"u_table_row_bits": TABLE_ROW_BITS, **offsets}


def transfer_uniforms(transfer: Transfer) -> dict:
    """glsl/output/transfer.glsl's uniforms: the exponent and sRGB's constants, float32."""
    exponent = 1.0 / (SRGB_EXPONENT if transfer.kind == "srgb" else transfer.gamma)
    return {"u_exponent": float(np.float32(exponent)),
            "u_srgb": tuple(float(np.float32(v)) for v in
                            (SRGB_LINEAR_LIMIT, SRGB_SLOPE, 1.0 + SRGB_A, SRGB_A))}


class OutputPass:
    """The GPU output stage of one context; see the module docstring."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self.last_milliseconds = 0.0
        self._programs: dict[tuple, moderngl.ComputeShader] = {}
        self._images: dict[tuple, tuple[moderngl.Texture, moderngl.Texture]] = {}
        self._tables: dict[tuple, tuple[moderngl.Texture, dict]] = {}
        self._blue_noise: moderngl.Buffer | None = None
        self._errors: dict[tuple, moderngl.Texture] = {}
        self._shares: dict[str, moderngl.Texture] = {}
        self._grid_thresholds: dict[tuple, moderngl.Texture] = {}

    # -- GL objects, each made once ------------------------------------------------------------
    def program(self, settings: OutputSettings) -> moderngl.ComputeShader:
        """The compiled program that runs `settings` (made on first use)."""
        activate(self.ctx)              # another context may be current: compile on ours
        defines = output_defines(settings)
        key = tuple(sorted(defines.items()))
        program = self._programs.get(key)
        if program is None:
            filename = ("output/error_diffusion.comp" if settings.dither in ERROR_DIFFUSION
                        else "output/output.comp")
            program = self._programs[key] = compute_program(self.ctx, filename,
                                                            defines | PASS_CONSTANTS)
        return program

    def _image_pair(self, width: int, height: int, quantised: bool):
        key = (width, height, quantised)
        pair = self._images.get(key)
        if pair is None:
            source = self.ctx.texture((width, height), 4, dtype="f4")
            target = self.ctx.texture((width, height), 4, dtype="u2" if quantised else "f4")
            pair = self._images[key] = (source, target)
        return pair

    def _table_texture(self, transfer: Transfer, bits: int):
        key = (transfer, bits)
        if key not in self._tables:
            self._tables[key] = table_texture(self.ctx, transfer, bits)
        return self._tables[key]

    def _blue_noise_buffer(self) -> moderngl.Buffer:
        if self._blue_noise is None:
            ranks = blue_noise_ranks().astype(np.uint32)
            self._blue_noise = self.ctx.buffer(ranks.tobytes())
        return self._blue_noise

    def _error_image(self, width: int, height: int, reach: int) -> moderngl.Texture:
        """Error diffusion's errors: (W + 2 reach) x (H + reach) rgba32f, made zero; only the
        image's own pixels are ever written, so the border stays zero."""
        key = (width, height, reach)
        image = self._errors.get(key)
        if image is None:
            size = (width + 2 * reach, height + reach)
            image = self._errors[key] = self.ctx.texture(size, 4, dtype="f4")
            image.write(np.zeros((size[1], size[0], 4), np.float32))
        return image

    def _shares_texture(self, kernel: str) -> moderngl.Texture:
        """sender_weights(kernel) as a float texture: the taps along x, the sources' sides
        (left, right, below) along y, ((left (r + 1) + right) (r + 1) + below)."""
        texture = self._shares.get(kernel)
        if texture is None:
            shares = sender_weights(kernel)
            texture = self._shares[kernel] = self.ctx.texture(
                (shares.shape[-1], shares[..., 0].size), 1, shares.tobytes(), dtype="f4")
        return texture

    def _grid_thresholds_texture(self, halftone) -> tuple[np.ndarray, moderngl.Texture | None]:
        """(cells, texture): grid_screens(halftone), its arrays as a float texture (texel
        (x, y) = array[y, x]), None when no ink's screen lies on the pixel grid."""
        cells, thresholds = grid_screens(halftone)
        if thresholds is None:
            return cells, None
        key = (thresholds.shape[1], grid_turns(halftone))
        texture = self._grid_thresholds.get(key)
        if texture is None:
            texture = self._grid_thresholds[key] = self.ctx.texture(
                thresholds.shape[::-1], 1, thresholds.tobytes(), dtype="f4")
        return cells, texture

    def gl_objects(self) -> list:
        """Every GL object the pass holds (tests: a repeated apply() adds none)."""
        objects = [*self._programs.values(), *(t for pair in self._images.values() for t in pair),
                   *(texture for texture, _ in self._tables.values()), *self._errors.values(),
                   *self._shares.values(), *self._grid_thresholds.values()]
        return objects + ([self._blue_noise] if self._blue_noise is not None else [])

    # -- the stage ------------------------------------------------------------------------------
    def apply(self, linear: np.ndarray, settings: OutputSettings) -> np.ndarray:
        """Codes (H, W, 4) uint16 for a quantised format, else encoded float32 (H, W, 4)."""
        start = time.perf_counter()
        linear = np.ascontiguousarray(linear, dtype=np.float32)
        if linear.ndim != 3 or linear.shape[2] != 4:
            raise ValueError(f"the output stage takes (H, W, 4) linear colour, got {linear.shape}")
        height, width = linear.shape[:2]
        activate(self.ctx)
        program = self.program(settings)
        source, target = self._image_pair(width, height, settings.quantised)
        source.write(linear)
        source.bind_to_image(INPUT_IMAGE, read=True, write=False)
        target.bind_to_image(OUTPUT_IMAGE, read=False, write=True)
        self._set_uniforms(program, settings)
        if settings.dither in ERROR_DIFFUSION:
            self._diffuse(program, settings, width, height)
        else:
            program.run((width + GROUP_SIZE - 1) // GROUP_SIZE,
                        (height + GROUP_SIZE - 1) // GROUP_SIZE)
        self.ctx.memory_barrier()
        out = np.empty((height, width, 4), np.uint16 if settings.quantised else np.float32)
        target.read_into(out)
        self.last_milliseconds = (time.perf_counter() - start) * 1000.0
        return out

    def _set_uniforms(self, program: moderngl.ComputeShader, settings: OutputSettings) -> None:
        values = transfer_uniforms(settings.transfer)    # float output; codes' first guess
        if settings.quantised:
            bits = settings.code_bits
            texture, uniforms = self._table_texture(settings.transfer, bits)
            texture.use(TABLES_UNIT)
            values |= {"u_bits": bits, "u_tables": TABLES_UNIT, **uniforms}
            if settings.dither == "blue-noise":
                self._blue_noise_buffer().bind_to_storage_buffer(BLUE_NOISE_BUFFER)
                values["u_blue_noise_size"] = blue_noise_ranks().shape[0]
            if settings.halftone is not None:
                program["u_screen"].write(screen_basis(settings.halftone))
                cells, texture = self._grid_thresholds_texture(settings.halftone)
                program["u_grid_cell"].write(cells)
                if texture is not None:         # else no ink reads it
                    texture.use(GRID_THRESHOLDS_UNIT)
                values["u_grid_thresholds"] = GRID_THRESHOLDS_UNIT
        for name, value in values.items():
            uniform = program.get(name, None)     # the compiler drops what a variant never reads
            if uniform is not None:
                uniform.value = value

    def _diffuse(self, program, settings: OutputSettings, width: int, height: int) -> None:
        """Error diffusion: one dispatch per wavefront t = x + s y, in order, with a memory
        barrier between them (the next reads what this one wrote), W + s (H - 1) dispatches
        (glsl/output/error_diffusion.comp; renderer/core/error_kernels.py)."""
        kernel = KERNELS[settings.dither]
        taps = pull_taps(settings.dither)
        tap_offsets = np.zeros((MAX_TAPS, 2), np.int32)
        tap_offsets[:len(taps)] = taps
        program["u_tap_offset"].write(tap_offsets)
        program["u_taps"].value = len(taps)
        self._shares_texture(settings.dither).use(SHARES_UNIT)
        program["u_shares"].value = SHARES_UNIT
        program["u_skew"].value = kernel.skew
        program["u_reach"].value = kernel.reach
        self._error_image(width, height, kernel.reach).bind_to_image(ERROR_IMAGE, read=True,
                                                                     write=True)
        wavefront = program["u_wavefront"]
        for t, first, last in wavefronts(width, height, kernel.skew):
            wavefront.value = (t, first, last)
            program.run((last - first) // WAVEFRONT_GROUP + 1)
            self.ctx.memory_barrier()

    def release(self) -> None:
        activate(self.ctx)
        for obj in self.gl_objects():
            obj.release()
        self._programs.clear()
        self._images.clear()
        self._tables.clear()
        self._errors.clear()
        self._shares.clear()
        self._grid_thresholds.clear()
        self._blue_noise = None
