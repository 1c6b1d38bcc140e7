"""DIR/manifest.jsonl: what a batch job has finished, and how a re-run resumes it.

JSON Lines, one object per line (renderer/core/jsonio.py `to_json`). Line 1 is the header:

    {"manifest": "renderer batch", "format": 1, "job": JOB_SHA256, "job_file": "orbit.toml",
     "name": "orbit", "renderer": "0.9.0", "items": 48}

`job` is items.job_identity: the SHA-256 of the canonical expanded items (keys, seeds, the
scenes' parsed contents after overrides, cameras, settings). Then one record per finished
item, appended by the driver (never a worker) after the item's files are in place:

    {"key": "hierarchy/orbit-007/sweep-000/raster", "seed": 2795193123,
     "setting": {...Setting.describe()}, "camera": {...CameraSpec.describe()},
     "overrides": {"objects[0].material.kd": [1, 0, 0]},
     "outputs": [{"path": "items/hierarchy/orbit-007/sweep-000/raster/image.png",
                  "sha256": FILE_BYTES_SHA256, "pixels_sha256": PIXELS_SHA256}],
     "render_ms": 12.5, "encode_ms": 3.1,
     "worker": {"host": "node1", "pid": 4242, "gl_renderer": "llvmpipe (LLVM 15.0.6, 256 bits)"},
     "compare": {...figures, as `renderer compare` prints them}}          (with --compare)

`sha256` is of the file's bytes, `pixels_sha256` of the array written (shape, dtype and
bytes: render_item.pixels_sha256), which stays the same where another zlib would compress the
same pixels to other bytes. Paths are relative to DIR, with '/'.

Resume (`read_manifest`): a record counts when its key is one of the job's items, its
outputs start with the item's files (with --compare, the comparison's too), and every file
it lists exists with that SHA-256; the other items are rendered again. A line that is not
whole JSON (the last one, cut by a kill) is ignored, and `Manifest.begin` rewrites the file
with the header and the records that count. A manifest whose header is another job's (or
not a batch manifest at all) is a UserError naming DIR/manifest.jsonl, exit status 2,
before anything is written: a job never mixes its files with another's.

A tampered record is never followed: one with a path that leaves DIR (absolute, '..',
through a symbolic link) or names something other than a regular file (a FIFO, a device,
a link) is dropped unread, said in one warning line for all of them (`Resume.warning`), and
its item rendered again; no file outside DIR is read or hashed (folder.py). The manifest
itself is read as a user's file (renderer/core/user_files.py: a regular file within its
cap), never through a link.
"""

from __future__ import annotations

import json
import os
import stat
from dataclasses import dataclass, field
from pathlib import Path

from renderer import __version__
from renderer.batch.folder import file_kind, regular_inside, sha256_inside
from renderer.core.imageio import outputs, remove_stale_temporaries
from renderer.core.jsonio import to_json
from renderer.core.paths import show_path
from renderer.core.user_files import MANIFEST_FILE, FileRefused, open_user_file, read_capped, refuse
from renderer.errors import SystemFault, UserError

MANIFEST = "manifest.jsonl"
KIND = "renderer batch"
FORMAT = 1


def file_sha256(path: Path) -> str | None:
    """SHA-256 of a regular file's bytes (a link is not followed), None when it cannot be read."""
    return sha256_inside(path.parent, path.name)


def header_for(job, identity: str, count: int) -> dict:
    return {"manifest": KIND, "format": FORMAT, "job": identity,
            "job_file": Path(job.path).name, "name": job.name, "renderer": __version__,
            "items": count}


@dataclass
class Resume:
    """What DIR holds of this job: the header to keep, the records that count (by key),
    and whether the file must be rewritten (lines dropped) before records are appended."""
    path: Path
    header: dict
    records: dict[str, dict] = field(default_factory=dict)
    rewrite: bool = True             # no manifest yet, or lines to drop
    refused: int = 0                 # records dropped for a path outside DIR or not a file

    def warning(self) -> str | None:
        """The one line for the records dropped unread, or None."""
        if not self.refused:
            return None
        records = "record names" if self.refused == 1 else "records name"
        return (f"warning: {self.path}: {self.refused} {records} a file outside the output "
                f"folder or not a regular file; dropped unread, their items are rendered again")


def _lines(path: Path) -> list[str] | None:
    """The manifest's lines, None when there is none. Read as a user's file (a regular file
    within its cap, user_files.py), and never through a symbolic link."""
    kind = file_kind(path)
    if kind is None:
        return None
    if kind == stat.S_IFLNK:
        raise UserError("is a symbolic link, not a batch manifest; give another --out",
                        file=show_path(path))
    try:
        with open_user_file(path, MANIFEST_FILE) as handle:
            return read_capped(handle, MANIFEST_FILE).decode("utf-8").split("\n")
    except FileRefused as refused:
        raise refuse(refused, path) from None
    except UnicodeDecodeError as error:
        raise UserError(f"cannot read it as a batch manifest ({error}); give another --out",
                        file=str(path)) from None


def _parsed(line: str):
    """The line's JSON, or None when it is not JSON as written here: NaN and Infinity, which
    Python's parser takes but to_json never writes (and refuses when the file is rewritten),
    are not; nor is nesting too deep to parse."""
    try:
        return json.loads(line, parse_constant=_no_constant)
    except (ValueError, RecursionError):
        return None


def _no_constant(name: str):
    raise ValueError(f"{name} is not JSON")


def _check_header(path: Path, found, header: dict) -> None:
    if not isinstance(found, dict) or found.get("manifest") != KIND:
        raise UserError("is not a renderer batch manifest; give another --out (a new folder, "
                        "or this job's own)", file=str(path))
    if found.get("job") != header["job"]:
        raise UserError(f"holds another job's manifest ({found.get('name')!r} from "
                        f"{found.get('job_file')}, {found.get('items')} items); give another "
                        f"--out, or remove that folder to start again", file=str(path))
    if found.get("format") != FORMAT or found.get("renderer") != header["renderer"]:
        raise UserError(f"was written by renderer {found.get('renderer')} (manifest format "
                        f"{found.get('format')}), not {header['renderer']}; its files may "
                        f"differ from this version's: give another --out", file=str(path))


def read_manifest(out: Path, header: dict, wanted: dict[str, list[str]]) -> Resume:
    """The manifest in `out` for this job's `header`, nothing written: `wanted` maps each
    item's key to the paths (under `out`) its record must list. Records that do not count
    are left out (module docstring)."""
    path = out / MANIFEST
    lines = _lines(path)
    if lines is None or lines == [""]:
        return Resume(path, header)
    _check_header(path, _parsed(lines[0]), header)
    body, dropped = lines[1:], lines[-1] != ""      # whole lines end with a line break
    records, refused = {}, 0
    for line in body[:-1] if not dropped else body:
        record = _parsed(line)
        listed = record.get("outputs") if isinstance(record, dict) else None
        if isinstance(listed, list) and not _confined(out, listed):
            refused += 1
            dropped = True
        elif isinstance(record, dict) and _counts(out, record, wanted):
            dropped |= record["key"] in records      # a later record of a key wins
            records[record["key"]] = record
        else:
            dropped = True
    return Resume(path, header, records, rewrite=dropped, refused=refused)


def _confined(out: Path, listed: list) -> bool:
    """Whether every path the record lists stays in DIR and is a regular file or missing
    (folder.regular_inside: looked at, not opened)."""
    return all(regular_inside(out, o.get("path")) is not False for o in listed
               if isinstance(o, dict))


def _counts(out: Path, record: dict, wanted: dict[str, list[str]]) -> bool:
    """Whether the record lists the item's files first (then maybe more: a record made with
    --compare counts for a run without) and every file it lists is as recorded."""
    key = record.get("key")
    files = wanted.get(key) if isinstance(key, str) else None     # a list is no key (unhashable)
    listed = record.get("outputs")
    if files is None or not isinstance(listed, list) or not all(isinstance(o, dict) for o in listed) \
            or [o.get("path") for o in listed][:len(files)] != files:
        return False
    return all(sha256_inside(out, o["path"]) == o.get("sha256") for o in listed)


class Manifest:
    """The manifest being written: `begin` puts the header and the kept records in place
    (atomically, when lines must go), `append` adds one record, flushed and fsync'd."""

    def __init__(self, resume: Resume):
        self.path = resume.path
        self.records = dict(resume.records)
        self._resume = resume

    def begin(self) -> "Manifest":
        remove_stale_temporaries(self.path)
        if self._resume.rewrite:
            text = "".join(to_json(line) + "\n" for line in
                           [self._resume.header, *self.records.values()])
            with outputs() as out:
                out.text(self.path, text)
        return self

    def append(self, record: dict) -> None:
        line = (to_json(record) + "\n").encode("utf-8")
        try:                    # not through a link: begin() put a regular file here
            fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT | os.O_NOFOLLOW
                         | os.O_NONBLOCK | os.O_CLOEXEC, 0o666)
            with os.fdopen(fd, "wb") as handle:
                handle.write(line)
                handle.flush()
                os.fsync(handle.fileno())
        except OSError as error:
            raise SystemFault(f"cannot write: {(error.strerror or str(error)).lower()}",
                              file=str(self.path)) from None
        self.records[record["key"]] = record
