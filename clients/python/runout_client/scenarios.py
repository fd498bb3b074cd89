"""Scenarios on the client side: reading one, and finding the local files its inputs name.

A scenario names its inputs by path (relative to the scenario file's folder). Before submitting,
the client uploads each input with its companion files and replaces the path by the upload's
reference ("upload:ID/NAME"), exactly as the C++ client does (service/client/client.cpp,
``upload_inputs``, with the field list of jobs/scenario/inputs.hpp): the paths uploaded are
``dem.path``, ``area_of_interest.path``, every ``releases[].path`` and ``releases[].thickness_raster``,
``observations.outline_path`` and ``path.line_path``;
the companions are the files beside the input with the same stem and one of
the extensions in :data:`COMPANION_EXTENSIONS` (``NAME.aux.xml`` for GDAL's PAM file).
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping, Union

import grpc
from google.protobuf import json_format

from ._proto import scenario_pb2
from .errors import RunoutError

#: A scenario as the client takes it: a JSON file's path, a dict in the JSON form (field names as
#: in the .proto or lowerCamelCase), or a runout.v1.Scenario message.
ScenarioLike = Union[str, os.PathLike, Mapping[str, Any], scenario_pb2.Scenario]

#: Files uploaded with an input when they lie beside it (a shapefile's .shx, .dbf, .prj, .cpg, .qix;
#: a raster's .prj, .hdr, .tfw and GDAL's NAME.aux.xml), in the C++ client's order.
COMPANION_EXTENSIONS = (".shx", ".dbf", ".prj", ".cpg", ".qix", ".aux.xml", ".hdr", ".tfw")

#: The prefix of an upload reference; such a path is sent as it is.
UPLOAD_PREFIX = "upload:"


@dataclass
class InputField:
    """One input path of a scenario: where it is (``field``, e.g. ``releases[0].path``), the
    message that holds it and the path as written."""

    field: str
    holder: Any
    path: str
    attribute: str = "path"  #: the holder's field that holds the path

    def set(self, value: str) -> None:
        """Replace the path in the scenario (e.g. by an upload reference)."""
        setattr(self.holder, self.attribute, value)
        self.path = value


def load_scenario(scenario: ScenarioLike, base_dir: str | os.PathLike | None = None) -> tuple[scenario_pb2.Scenario, Path]:
    """Read a scenario; returns a new Scenario message and the folder its relative paths start in.

    The folder is ``base_dir`` when given, else the scenario file's folder (for a path) or the
    current folder (for a dict or a message). The JSON is read as the server and ``runout submit``
    read it: protobuf's JSON mapping, unknown fields and duplicate keys refused. A scenario that
    cannot be read raises RunoutError with INVALID_ARGUMENT (before anything is sent).
    """
    s = scenario_pb2.Scenario()
    if isinstance(scenario, scenario_pb2.Scenario):
        s.CopyFrom(scenario)
        where = Path.cwd()
    elif isinstance(scenario, Mapping):
        try:
            json_format.ParseDict(scenario, s, ignore_unknown_fields=False)
        except json_format.ParseError as e:
            raise RunoutError(grpc.StatusCode.INVALID_ARGUMENT, f"scenario JSON: {e}", "scenario") from None
        where = Path.cwd()
    elif isinstance(scenario, (str, os.PathLike)):
        p = Path(scenario)
        try:
            text = p.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as e:
            raise RunoutError(grpc.StatusCode.INVALID_ARGUMENT, f"cannot read scenario '{p}': {e}", "scenario") from None
        try:
            json_format.Parse(text, s, ignore_unknown_fields=False)
        except json_format.ParseError as e:
            raise RunoutError(grpc.StatusCode.INVALID_ARGUMENT, f"scenario '{p}': scenario JSON: {e}", "scenario") from None
        where = p.resolve().parent
    else:
        raise TypeError(f"a scenario is a JSON file's path, a dict or a runout.v1.Scenario, not {type(scenario).__name__}")
    return s, Path(base_dir).resolve() if base_dir is not None else where


def input_fields(s: scenario_pb2.Scenario) -> list[InputField]:
    """The input paths the client uploads, in the C++ client's order (jobs/scenario/inputs.hpp):
    dem.path, area_of_interest.path (when the scenario has one), releases[k].path and
    releases[k].thickness_raster, observations.outline_path, path.line_path. Empty paths are left out (the server names
    what is missing)."""
    out = [InputField("dem.path", s.dem, s.dem.path)]
    if s.HasField("area_of_interest"):
        out.append(InputField("area_of_interest.path", s.area_of_interest, s.area_of_interest.path))
    for k, r in enumerate(s.releases):
        out.append(InputField(f"releases[{k}].path", r, r.path))
        out.append(InputField(f"releases[{k}].thickness_raster", r, r.thickness_raster, "thickness_raster"))
    if s.HasField("observations"):
        out.append(InputField("observations.outline_path", s.observations, s.observations.outline_path, "outline_path"))
    if s.HasField("path"):
        out.append(InputField("path.line_path", s.path, s.path.line_path, "line_path"))
    return [f for f in out if f.path]


def local_files(path: str, base_dir: Path, files: Mapping[str, str | os.PathLike] | None = None) -> list[Path]:
    """The files to upload for one input path: the input itself first, then its companions.

    ``files`` may map a path as the scenario writes it to the local file that holds it (the
    companions are then looked for beside that file); otherwise a relative path starts in
    ``base_dir``. Raises RunoutError (INVALID_ARGUMENT) when the input is not a regular file.
    """
    if files is not None and path in files:
        p = Path(files[path]).resolve()  # a relative local path: from the current folder
    else:
        p = Path(path) if Path(path).is_absolute() else base_dir / path
    if not p.is_file():
        raise RunoutError(grpc.StatusCode.INVALID_ARGUMENT, f"input '{p}' does not exist or is not a file", "upload")
    out = [p]
    for ext in COMPANION_EXTENSIONS:
        side = p.with_name(p.name + ext) if ext == ".aux.xml" else p.with_suffix(ext)
        if side != p and side.is_file():
            out.append(side)
    return out
