"""Counts the manual states about the tree agree with the tree (issue 31: "four" ray-tracing
scenes in three places when there were eight, "47 goldens and 4 ray-traced" when there were
77 and 8). Each claim the pages make is a pattern here with the count it must equal; a count
in words or digits ("eight", "92"). A dated measurement ("2971 tests in 541 s, 2026-12-02")
is no claim about the tree and is not read."""

import re
from pathlib import Path

from renderer.core.builtin import builtin_scenes, made_for

from test_readme import manual

ROOT = Path(__file__).resolve().parents[1]
WORDS = {word: n for n, word in enumerate(
    "zero one two three four five six seven eight nine ten eleven twelve thirteen fourteen "
    "fifteen sixteen seventeen eighteen nineteen twenty".split())}
NUMBER = r"(\d[\d,]*|" + "|".join(WORDS) + ")"


def value(text: str) -> int:
    return WORDS[text] if text in WORDS else int(text.replace(",", ""))


def goldens() -> list[str]:
    return sorted(path.stem for path in (ROOT / "tests" / "goldens").glob("*.png"))


def tree_counts() -> dict[str, int]:
    """Each claim's pattern (NUMBER where the count stands) and the count the tree gives."""
    ray_traced = [name for name in builtin_scenes() if made_for(name) == "raytrace"]
    radiated = [name for name in builtin_scenes() if made_for(name) == "radiosity"]
    return {
        rf"\b{NUMBER} scenes made for the ray tracer": len(ray_traced),
        rf"\b{NUMBER} scenes made for radiosity": len(radiated),
        rf"\b{NUMBER} goldens at 256×256": len([g for g in goldens()
                                                 if not g.endswith(("-raytrace", "-radiosity", "-pathtrace"))]),
        rf"\b{NUMBER} ray-traced ones": len([g for g in goldens() if g.endswith("-raytrace")]),
        rf"\b{NUMBER} radiosity ones": len([g for g in goldens() if g.endswith("-radiosity")]),
        rf"\b{NUMBER} path-traced ones": len([g for g in goldens() if g.endswith("-pathtrace")]),
        rf"\b{NUMBER} more, {NUMBER} in all": None,            # read by its own rule below
        rf"\b{NUMBER} built-in scenes are made for the ray tracer": len(ray_traced),
        rf"\b{NUMBER} built-in scenes are textured": len(textured_scenes()),
    }


def textured_scenes() -> list[str]:
    from renderer.core.scene_file import load_scene
    return [name for name, path in builtin_scenes().items()
            if any(obj.material.texture is not None for obj in load_scene(path).objects)]


def pages() -> dict[str, str]:
    """The README and the manual's pages (not the committed reports: each is dated, its counts
    those of its day), their lines joined."""
    return {name: " ".join(text.split()) for name, text in manual().items()
            if not name.startswith("docs/report/")}


def wrong_counts(texts: dict[str, str], counts: dict[str, int]) -> list[str]:
    wrong = []
    for name, text in texts.items():
        for pattern, count in counts.items():
            for match in re.finditer(pattern, text, re.I):
                if count is not None and value(match.group(1).lower()) != count:
                    wrong.append(f"{name}: {match.group(0)!r}: the tree has {count}")
    return wrong


def test_the_manual_counts_what_the_tree_holds():
    texts, counts = pages(), tree_counts()
    assert all(any(re.search(pattern, text, re.I) for text in texts.values()) for pattern in counts)
    assert wrong_counts(texts, counts) == []


def test_the_goldens_add_up():
    """"N more, M in all": the ray-traced, radiosity and path-traced goldens beside the 256×256 ones."""
    in_all = len(goldens())
    beside = len([g for g in goldens() if g.endswith(("-raytrace", "-radiosity", "-pathtrace"))])
    for name, text in pages().items():
        for more, total in re.findall(rf"\b{NUMBER} more, {NUMBER} in all", text):
            assert (value(more), value(total)) == (beside, in_all), name


def test_the_check_sees_a_stale_count():
    counts = {rf"\b{NUMBER} scenes made for the ray tracer": 8}
    assert wrong_counts({"p.md": "the four scenes made for the ray tracer"}, counts) == [
        "p.md: 'four scenes made for the ray tracer': the tree has 8"]
    assert wrong_counts({"p.md": "the eight scenes made for the ray tracer"}, counts) == []
