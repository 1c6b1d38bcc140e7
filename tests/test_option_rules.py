"""Each option rule exists once: in the options object's constructor (renderer/core/ray_options.py
RayOptions, renderer/core/output_settings.py OutputSettings, renderer/methods for which method
takes which option). The command line and the job file only spell the fields their own way
(`--spp 2 --pattern adaptive`, `settings[0].samples`); the reason after the spelling is the
same line from both, and the one the options object gives when made directly.

Every refusal of docs/bad-input.md's ray-tracer, lens and output-stage rows that a job file can
express is fed through both front ends here; the others are listed in CLI_ONLY with why."""

import re
from pathlib import Path

import pytest

from renderer.batch.job_file import read_job
from renderer.core.output_settings import OutputSettings, parse_halftone
from renderer.core.ray_options import RayOptions
from renderer.errors import OptionError, UserError
from renderer.methods import method_options

ROOT = Path(__file__).resolve().parents[1]

# (command line options, the job file's [[settings]] lines, the options object made directly)
RULES = {
    "spp 0": (["--method", "raytrace", "--spp", "0"], 'method = "raytrace"\nsamples = 0',
              lambda: RayOptions(samples=0)),
    "max depth 65": (["--method", "raytrace", "--max-depth", "65"], 'method = "raytrace"\nmax_depth = 65',
                     lambda: RayOptions(max_depth=65)),
    "max depth -1": (["--method", "raytrace", "--max-depth", "-1"], 'method = "raytrace"\nmax_depth = -1',
                     lambda: RayOptions(max_depth=-1)),
    "adaptive spp 2": (["--method", "raytrace", "--pattern", "adaptive", "--spp", "2"],
                       'method = "raytrace"\npattern = "adaptive"\nsamples = 2',
                       lambda: RayOptions(pattern="adaptive", samples=2)),
    "unknown pattern": (["--method", "raytrace", "--pattern", "hexagonal"],
                        'method = "raytrace"\npattern = "hexagonal"', lambda: RayOptions(pattern="hexagonal")),
    "regular spp 3": (["--method", "raytrace", "--spp", "3"], 'method = "raytrace"\nsamples = 3',
                      lambda: RayOptions(samples=3)),
    "light samples 0": (["--method", "raytrace", "--light-samples", "0"],
                        'method = "raytrace"\nlight_samples = 0', lambda: RayOptions(light_samples=0)),
    "light samples 65": (["--method", "raytrace", "--light-samples", "65"],
                         'method = "raytrace"\nlight_samples = 65', lambda: RayOptions(light_samples=65)),
    "threshold without adaptive": (["--method", "raytrace", "--pattern", "jittered", "--adaptive-threshold", "0.1"],
                                   'method = "raytrace"\npattern = "jittered"\nadaptive_threshold = 0.1',
                                   lambda: RayOptions(pattern="jittered", adaptive_threshold=0.1)),
    "negative threshold": (["--method", "raytrace", "--pattern", "adaptive", "--spp", "4",
                            "--adaptive-threshold", "-1"],
                           'method = "raytrace"\npattern = "adaptive"\nsamples = 4\nadaptive_threshold = -1.0',
                           lambda: RayOptions(pattern="adaptive", samples=4, adaptive_threshold=-1.0)),
    "ray option for raster": (["--spp", "4"], 'samples = 4', lambda: method_options("raster", {"samples": 4})),
    "bits 17": (["--bits", "17"], "outputs = [{ bits = 17 }]", None),
    "png8 bits 12": (["--format", "png8", "--bits", "12"], 'outputs = [{ format = "png8", bits = 12 }]',
                     lambda: OutputSettings(format="png8", bits=12)),
    "exr bits 4": (["--format", "exr", "--bits", "4"], 'outputs = [{ format = "exr", bits = 4 }]',
                   lambda: OutputSettings(format="exr", bits=4)),
    "halftone and dither": (["--halftone", "6", "--dither", "bayer4"],
                            'outputs = [{ halftone = "6", dither = "bayer4" }]',
                            lambda: OutputSettings(halftone=parse_halftone("6"), dither="bayer4")),
    "halftone 1.5": (["--halftone", "1.5"], 'outputs = [{ halftone = "1.5" }]', None),
    "halftone 100000": (["--halftone", "100000"], 'outputs = [{ halftone = "100000" }]', None),
    "halftone 8:1e300": (["--halftone", "8:1e300"], 'outputs = [{ halftone = "8:1e300" }]', None),
    "transfer gamma -2": (["--transfer", "gamma:-2"], 'outputs = [{ transfer = "gamma:-2" }]', None),
    "exr transparent": (["--format", "exr", "--background", "transparent"],
                        'background = "transparent"\noutputs = [{ format = "exr" }]',
                        lambda: OutputSettings(format="exr").check_background("transparent")),
}

# Refusals of the rows that only the command line can be given, and why.
CLI_ONLY = {
    "--aperture": "a job's cameras are its scenes': a lens is a scene file's [camera] keys",
    "--focus-distance": "as --aperture",
    "--dither": "the job file refuses an unknown name as any choice key (did you mean ...?)",
    "-o": "a job names its files by outputs[].name; the command line's -o suffix rules are its own",
    "--alpha": "the job file writes no alpha file",
    "--depth": "a job's depth output is { depth = \"npy\" | \"exr\" }, a choice",
    "--method": "the lens row's `--aperture 0.3` with `--method raster`: an option of another "
                "method is held by 'ray option for raster'",
}


def reason_of(line: str, *prefixes: str) -> str:
    """The reason after the spelling: what follows the option words' ': '. (The command line
    says an option argparse took as `renderer render: ...` with the usage after it, one of
    the output stage's, parsed after argparse, as `renderer: ...`.)"""
    prefix = next((p for p in prefixes if line.startswith(p)), None)
    assert prefix is not None, line
    return line[len(prefix):].split(": ", 1)[1]


@pytest.mark.parametrize("cli_args, job_lines, direct", RULES.values(), ids=RULES.keys())
def test_the_command_line_and_the_job_file_give_the_same_reason(cli_here, tmp_path, cli_args, job_lines,
                                                                  direct):
    result = cli_here("render", "sphere", "--size", "8x6", "-o", tmp_path / "x.png", *cli_args)
    assert result.returncode == 2 and not (tmp_path / "x.png").exists(), result.stderr
    cli_line = result.stderr.splitlines()[0]
    job = tmp_path / "job.toml"
    job.write_text('[[scenes]]\nscene = "sphere"\n[[settings]]\n' + job_lines + "\n")
    with pytest.raises(UserError) as refused:
        read_job(job)
    job_line = refused.value.line()
    cli_reason = reason_of(cli_line, "renderer render: ", "renderer: ")
    job_reason = reason_of(job_line, f"{job}: ")
    assert cli_reason == job_reason, (cli_line, job_line)
    if direct is not None:
        with pytest.raises(OptionError) as made:
            direct()
        assert made.value.reason == cli_reason


def test_every_refusal_of_the_documented_rows_is_held_here():
    """docs/bad-input.md's ray-tracer, lens and output-stage rows: each command-line example is a
    rule above or a CLI_ONLY option."""
    rows = [line for line in (ROOT / "docs/bad-input.md").read_text().splitlines()
            if line.startswith(("| ray-tracer input", "| the thin lens", "| the output stage's options"))]
    assert len(rows) == 3
    examples = [e for row in rows for e in re.findall(r"`(-[^`]+)`", row.split(" | ")[1])]
    held = {" ".join(args) for args, _, _ in RULES.values()}
    missing = [e for e in examples
               if not any(all(word in h.split() for word in e.split()) for h in held)
               and e.split()[0] not in CLI_ONLY]
    assert examples and missing == []


def test_a_spelling_names_only_the_options_given(cli_here, tmp_path):
    """-o x.exr implies the format: the line names --bits alone, the reason says exr."""
    result = cli_here("render", "sphere", "--size", "8x6", "-o", tmp_path / "x.exr", "--bits", "4")
    assert result.stderr.splitlines() == [
        "renderer: --bits 4: exr holds float colour unquantised; quantise to png8 or png16"]
