"""`renderer shaders`: the exact GLSL a scene's draws use, one set of files per variant."""

from __future__ import annotations


from renderer.cli.options import load, memory_option, output_path


def add_parser(sub) -> None:
    """`shaders`' parser: the scene and --out."""
    shaders = sub.add_parser("shaders", help="write the exact GLSL a scene's draws use")
    shaders.add_argument("scene", nargs="?", help="scene file or built-in scene name (default: the default scene)")
    shaders.add_argument("--out", type=output_path, help="folder for VARIANT.vert/.tesc/.tese/.geom/.frag "
                                                   "(default: out/shaders-SCENE_NAME)")
    memory_option(shaders)


def run(args) -> int:
    """One set of files per shader variant the scene draws with, named after the variant,
    and a line per variant naming the objects that use it."""
    from renderer.core.drawn import triangle_bound
    from renderer.core.imageio import check_folder, outputs
    from renderer.core.paths import default_output, output_stem
    from renderer.core.shadows import has_shadow_maps
    from renderer.gpu.shaders import ShaderVariant, program_sources
    if args.out is not None:
        check_folder(args.out)
    scene = load(args.scene)
    out = check_folder(args.out or default_output(f"shaders-{output_stem(scene)}"))
    users: dict[ShaderVariant, list[str]] = {}
    maps = has_shadow_maps(scene)
    for obj in scene.objects:
        if triangle_bound(obj):            # what the camera pass may draw (renderer/core/drawn.py)
            variant = ShaderVariant.for_object(scene, obj, maps=maps)
            users.setdefault(variant, []).append(obj.name)
    suffixes = {"vertex_shader": "vert", "tess_control_shader": "tesc", "tess_evaluation_shader": "tese",
                "geometry_shader": "geom", "fragment_shader": "frag"}
    lines = []
    with outputs() as written:                   # every variant's files or none
        for variant, names in users.items():
            files = []
            for stage, source in program_sources(variant).items():
                files.append(written.text(out / f"{variant.name}.{suffixes[stage]}", source.text).name)
            lines.append(f"{variant.name}: {', '.join(files)} (objects: {', '.join(names)})")
    for line in lines:
        print(line)
    return 0
