"""``model.json``: the identified models of one wheel on one soil, as one typed object.

A :class:`ModelSet` holds the longitudinal models by label (the paper's linear Eq. (14) and the
recommended quadratic one, ``fits.IdentifiedModel``), the lateral model (``lateral.LateralModel``,
None in files made before it existed) and where they came from (``details``: the plan, the FMU
and its SHA-256, the soil and wheel, the fit rule, failures). It is written and read here only
(:meth:`ModelSet.to_json`, :meth:`ModelSet.from_json`, :meth:`ModelSet.read`); the file carries
a ``schema_version`` so that a reader can refuse a file newer than it understands.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .fits import IdentifiedModel
from .lateral import LateralModel

#: Soil and wheel fields added after model files were first written, with the value those files were
#: identified with (the field's default: a soil without slip-sinkage, a smooth wheel).
FIELD_DEFAULTS: dict[str, dict[str, float]] = {"soil": {"n_slip": 0.0},
                                                "wheel": {"grouser_height": 0.0, "grouser_count": 0.0}}

#: Bumped when the layout of model.json changes; files without it are version 1 (the same layout).
SCHEMA_VERSION = 1


class ModelFileError(ValueError):
    """A model.json that cannot be read; the message names the file."""


class ModelMismatch(ValueError):
    """A model used on another soil or wheel than it was identified on; the message names both."""


@dataclass
class ModelSet:
    """The identified models of model.json (see the module docstring)."""

    recommended: str
    longitudinal: dict[str, IdentifiedModel]
    lateral: LateralModel | None = None
    #: Everything else the file records: lut_interpolation, fx_fit, plan, fmu, soil, wheel, failures;
    #: ``lateral_details``: the lateral model's plan, inputs and failures.
    details: dict[str, Any] = field(default_factory=dict)
    source: str = "model.json"  # where it was read from, for messages

    def __post_init__(self) -> None:
        if self.recommended not in self.longitudinal:
            raise ModelFileError(f"{self.source}: recommended model {self.recommended!r} is not among its models "
                                 f"{sorted(self.longitudinal)}")

    def model(self, label: str | None = None) -> IdentifiedModel:
        """The longitudinal model ``label`` (default: the recommended one)."""
        label = label or self.recommended
        if label not in self.longitudinal:
            raise ModelFileError(f"{self.source}: model {label!r} not in it (has {sorted(self.longitudinal)})")
        return self.longitudinal[label]

    def mismatch(self, soil: dict[str, float], wheel: dict[str, float], soil_name: str = "?",
                 wheel_name: str = "?") -> str | None:
        """Why the models do not belong to the soil and wheel given (their values, SI, as
        ``dataclasses.asdict`` gives them), or None: they were identified on them (or the file
        does not say what they were identified on)."""
        known_soil = self.details.get("soil", {}).get("values")
        known_wheel = self.details.get("wheel", {}).get("values")
        problems = []
        for kind, known, given, name in (("soil", known_soil, soil, soil_name), ("wheel", known_wheel, wheel,
                                                                                  wheel_name)):
            if known is None:
                continue
            # a file written before a field existed was identified with the field's default (e.g. a
            # smooth wheel before grousers, a soil without slip-sinkage)
            known = {**FIELD_DEFAULTS[kind], **known}
            differ = sorted(k for k in set(known) | set(given) if known.get(k) != given.get(k))
            if differ:
                identified = self.details.get(kind, {}).get("name", "?")
                problems.append(f"{kind} {identified!r} (identified on) is not {kind} {name!r} (in use): "
                                f"{', '.join(differ)} differ")
        if not problems:
            return None
        return (f"{self.source} was identified on another soil or wheel: {'; '.join(problems)}. Identify on this soil "
                "(rover-cosim identify --soil ...), or pass --allow-model-mismatch to use it anyway")

    def to_dict(self) -> dict[str, Any]:
        details = dict(self.details)
        lateral_details = details.pop("lateral_details", {})
        data: dict[str, Any] = {"schema_version": SCHEMA_VERSION, "recommended": self.recommended,
                                "models": {label: m.to_dict() for label, m in self.longitudinal.items()}, **details}
        if self.lateral is not None:
            data["lateral"] = {**self.lateral.to_dict(), **lateral_details}
        return data

    def to_json(self) -> bytes:
        """model.json's text: indented JSON, UTF-8, ending in a newline."""
        return (json.dumps(self.to_dict(), indent=2, default=str) + "\n").encode()

    @staticmethod
    def from_json(text: str | bytes, source: str = "model.json") -> ModelSet:
        """The ModelSet of model.json's ``text``; ModelFileError naming ``source`` when it is not one."""
        try:
            data = json.loads(text)
        except ValueError as error:
            raise ModelFileError(f"{source}: not a JSON file ({error})") from None
        if not isinstance(data, dict):
            raise ModelFileError(f"{source}: expected a JSON object (an identified model from `rover-cosim identify`)")
        version = data.get("schema_version", 1)
        if not isinstance(version, int) or version > SCHEMA_VERSION:
            raise ModelFileError(f"{source}: schema_version {version!r}: this rover-cosim reads model files up to "
                                 f"version {SCHEMA_VERSION} (identify again, or update rover-cosim)")
        try:
            longitudinal = {label: IdentifiedModel.from_dict(m) for label, m in data["models"].items()}
            lateral_data = data.get("lateral")
            lateral = LateralModel.from_dict(lateral_data) if lateral_data is not None else None
            recommended = data["recommended"]
        except (KeyError, TypeError, ValueError, AttributeError) as error:
            raise ModelFileError(f"{source}: not an identified model ({type(error).__name__}: {error})") from None
        known = {"schema_version", "recommended", "models", "lateral"}
        details = {k: v for k, v in data.items() if k not in known}
        if lateral_data is not None:
            own = set(LateralModel.from_dict(lateral_data).to_dict())
            details["lateral_details"] = {k: v for k, v in lateral_data.items() if k not in own}
        return ModelSet(recommended, longitudinal, lateral, details, source)

    @staticmethod
    def read(path: str | Path) -> ModelSet:
        """model.json at ``path``; ModelFileError naming it when missing or not one."""
        path = Path(path)
        try:
            text = path.read_bytes()
        except FileNotFoundError:
            raise ModelFileError(f"identified model {path} not found (make it with `rover-cosim identify`)") from None
        except OSError as error:
            raise ModelFileError(f"identified model {path}: cannot be read ({error})") from None
        return ModelSet.from_json(text, str(path))
