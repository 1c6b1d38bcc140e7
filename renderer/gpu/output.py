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

GL objects are made on first use and kept: a program per set of defines (program_defines:
settings.defines(), so that a program holds only the method it runs, less the transfer of
codes, which the tables carry), the input and output images per size and kind,
the quantisation tables per (transfer, bits) (one SSBO, renderer/core/quantise.py), the
blue-noise ranks once, error diffusion's error image per size and shares per kernel. A second apply() with settings
and a size seen before makes no GL object. Error diffusion runs its own program in wavefronts
(`_diffuse`).
"""

from __future__ import annotations

import time

import moderngl
import numpy as np

from renderer.core.blue_noise import blue_noise_ranks
from renderer.core.error_kernels import KERNELS, pull_taps, sender_weights, wavefronts
from renderer.core.halftone_screen import screen_basis
from renderer.core.output_settings import ERROR_DIFFUSION, OutputSettings, Transfer
from renderer.core.quantise import (SRGB_A, SRGB_EXPONENT, SRGB_LINEAR_LIMIT, SRGB_SLOPE,
                                    code_values, decision_points)
from renderer.gpu.context import activate
from renderer.gpu.shaders import ShaderSourceError, shader_source

GROUP_SIZE = 8                       # output.comp's local_size_x and _y
WAVEFRONT_GROUP = 64                 # error_diffusion.comp's local_size_x
MAX_TAPS = 12                        # error_diffusion.comp's tap arrays
LINEAR = Transfer("linear")
# Bindings, as the GLSL declares them: images 0 (input), 1 (output) and 2 (error diffusion's
# errors); SSBOs 0 (tables), 1 (blue-noise ranks), 2 (error diffusion's shares).
INPUT_IMAGE, OUTPUT_IMAGE, ERROR_IMAGE = 0, 1, 2
TABLES_BUFFER, BLUE_NOISE_BUFFER, WEIGHTS_BUFFER = 0, 1, 2


def table_layout(transfer: Transfer, bits: int) -> tuple[np.ndarray, dict[str, int]]:
    """The quantisation SSBO of (transfer, bits) and the uniforms naming where each table
    starts (glsl/output/quantise.glsl): decision points of the transfer, of the linear
    transfer (alpha), the codes' linear values."""
    tables = (decision_points(transfer, bits), decision_points(LINEAR, bits),
              code_values(transfer, bits))
    offsets = np.cumsum([0] + [len(t) for t in tables[:-1]])
    names = ("u_decision_points", "u_alpha_points", "u_code_values")
    return np.concatenate(tables), dict(zip(names, map(int, offsets)))


def transfer_uniforms(transfer: Transfer) -> dict:
    """glsl/output/transfer.glsl's uniforms: the exponent and sRGB's constants, float32."""
    exponent = 1.0 / (SRGB_EXPONENT if transfer.kind == "srgb" else transfer.gamma)
    return {"u_exponent": float(np.float32(exponent)),
            "u_srgb": tuple(float(np.float32(v)) for v in
                            (SRGB_LINEAR_LIMIT, SRGB_SLOPE, 1.0 + SRGB_A, SRGB_A))}


def program_defines(settings: OutputSettings) -> dict[str, str]:
    """settings.defines() less the transfer's where the output is quantised: codes come from
    the tables of (transfer, bits), so the define would only compile the same program again."""
    defines = settings.defines()
    if settings.quantised:
        defines = {name: value for name, value in defines.items() if not name.startswith("TRANSFER_")}
    return defines


class OutputPass:
    """The GPU output stage of one context; see the module docstring."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self.last_milliseconds = 0.0
        self._programs: dict[tuple, moderngl.ComputeShader] = {}
        self._images: dict[tuple, tuple[moderngl.Texture, moderngl.Texture]] = {}
        self._tables: dict[tuple, tuple[moderngl.Buffer, dict]] = {}
        self._blue_noise: moderngl.Buffer | None = None
        self._errors: dict[tuple, moderngl.Texture] = {}
        self._weights: dict[str, moderngl.Buffer] = {}

    # -- GL objects, each made once ------------------------------------------------------------
    def program(self, settings: OutputSettings) -> moderngl.ComputeShader:
        """The compiled program that runs `settings` (made on first use)."""
        activate(self.ctx)              # another context may be current: compile on ours
        defines = program_defines(settings)
        key = tuple(sorted(defines.items()))
        program = self._programs.get(key)
        if program is None:
            filename = ("output/error_diffusion.comp" if settings.dither in ERROR_DIFFUSION
                        else "output/output.comp")
            source = shader_source(filename, defines)
            try:
                program = self.ctx.compute_shader(source.text)
            except moderngl.Error as exc:
                files = ", ".join(f"{i}={name}" for i, name in enumerate(source.files))
                raise ShaderSourceError(f"{filename} with {defines} does not compile "
                                        f"(source strings {files}):\n{exc}") from None
            self._programs[key] = program
        return program

    def _image_pair(self, width: int, height: int, quantised: bool):
        key = (width, height, quantised)
        pair = self._images.get(key)
        if pair is None:
            source = self.ctx.texture((width, height), 4, dtype="f4")
            target = self.ctx.texture((width, height), 4, dtype="u2" if quantised else "f4")
            pair = self._images[key] = (source, target)
        return pair

    def _table_buffer(self, transfer: Transfer, bits: int):
        key = (transfer, bits)
        entry = self._tables.get(key)
        if entry is None:
            data, offsets = table_layout(transfer, bits)
            entry = self._tables[key] = (self.ctx.buffer(data.tobytes()), offsets)
        return entry

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

    def _weights_buffer(self, kernel: str) -> moderngl.Buffer:
        buffer = self._weights.get(kernel)
        if buffer is None:
            buffer = self._weights[kernel] = self.ctx.buffer(sender_weights(kernel).tobytes())
        return buffer

    def gl_objects(self) -> list:
        """Every GL object the pass holds (tests: a repeated apply() adds none)."""
        objects = [*self._programs.values(), *(t for pair in self._images.values() for t in pair),
                   *(buffer for buffer, _ in self._tables.values()), *self._errors.values(), *self._weights.values()]
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
        values = {}
        if settings.quantised:
            bits = settings.code_bits
            buffer, offsets = self._table_buffer(settings.transfer, bits)
            buffer.bind_to_storage_buffer(TABLES_BUFFER)
            values |= {"u_bits": bits, **offsets}
            if settings.dither == "blue-noise":
                self._blue_noise_buffer().bind_to_storage_buffer(BLUE_NOISE_BUFFER)
                values["u_blue_noise_size"] = blue_noise_ranks().shape[0]
            if settings.halftone is not None:
                program["u_screen"].write(screen_basis(settings.halftone))
        else:
            values |= transfer_uniforms(settings.transfer)
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
        self._weights_buffer(settings.dither).bind_to_storage_buffer(WEIGHTS_BUFFER)
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
        self._weights.clear()
        self._blue_noise = None
