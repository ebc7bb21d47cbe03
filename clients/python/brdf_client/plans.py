"""Measurement plans from Python dicts, JSON text or JSON files (examples/plans/*.json).

The JSON form is protobuf's JSON mapping of brdf.v1.Plan (plan.proto): lowerCamelCase field
names, e.g. {"sampleRotation": {"alpha": {"step": 10}}}. The original snake_case names are
accepted too. An unknown field is an error here, before anything reaches the daemon, so a typo
never silently falls back to a default.
"""

import json
import os
import pathlib
from typing import Any, Dict, Union

from google.protobuf import json_format

from ._stubs import plan_pb2


# What the client takes as a plan: a brdf.v1.Plan, a dict (its JSON form), JSON text, or the path
# of a JSON file.
PlanLike = Union[Any, Dict[str, Any], str, "os.PathLike[str]"]


def to_plan(plan: PlanLike) -> Any:
    """A brdf.v1.Plan from a Plan message, a dict, a JSON string or a path to a JSON file.

    Raises ValueError naming the source and the problem for unreadable JSON or unknown fields.
    (Whether the plan makes sense for the rig is the daemon's call: see BrdfClient.validate_plan.)
    """
    if isinstance(plan, plan_pb2.Plan):
        return plan
    source = "plan"
    if isinstance(plan, os.PathLike) or (isinstance(plan, str)
                                         and not plan.lstrip().startswith("{")):
        source = str(plan)
        try:
            plan = pathlib.Path(plan).read_text(encoding="utf-8")
        except OSError as e:
            raise ValueError(f"cannot read the plan file {source}: {e.strerror}") from e
    if isinstance(plan, str):
        try:
            plan = json.loads(plan)
        except json.JSONDecodeError as e:
            raise ValueError(f"{source}: not valid JSON at line {e.lineno}, column {e.colno}: "
                             f"{e.msg}") from e
    if not isinstance(plan, dict):
        raise ValueError(f"{source}: a plan is a JSON object (dict), not {type(plan).__name__}")
    try:
        return json_format.ParseDict(plan, plan_pb2.Plan())
    except json_format.ParseError as e:
        raise ValueError(f"{source}: {e} (plan fields: see proto/brdf/v1/plan.proto)") from e


def to_dict(plan: Any) -> Dict[str, Any]:
    """The JSON form of a Plan message (lowerCamelCase keys, unset fields left out)."""
    return json_format.MessageToDict(plan)
