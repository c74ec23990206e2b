"""Shared fixtures: a spindle-holder-tool model like the thesis's analytical case."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import settings

from substructure import (
    Assembly,
    Flutes,
    Frequency,
    Holder,
    Insert,
    Joint,
    NonPassiveJointWarning,
    Segment,
    Spindle,
    Tool,
)
from substructure.datasets import thesis_joint

# Property-based tests are deterministic (a fixed seed) and keep no example
# database, so that every run, here and in CI, tests the same cases.
settings.register_profile("substructure", derandomize=True, database=None, deadline=None)
settings.load_profile("substructure")


def make_spindle() -> Spindle:
    return Spindle(
        "spindle",
        [
            Segment("120 mm", "70 mm", "40 mm"),
            Segment("150 mm", "90 mm", "40 mm"),
            Segment("60 mm", "110 mm", "40 mm"),
        ],
    )


def make_holder() -> Holder:
    return Holder(
        "holder",
        [
            Segment("16 mm", "63 mm"),
            Segment("10 mm", "40 mm"),
            Segment("40 mm", "40 mm", "12 mm", insert=Insert("12 mm", "carbide")),
        ],
    )


def make_tool(overhang_mm: float = 60.0) -> Tool:
    return Tool(
        "tool",
        [
            Segment(f"{overhang_mm / 2} mm", "12 mm", material="carbide"),
            Segment(f"{overhang_mm / 2} mm", "12 mm", material="carbide", flutes=Flutes(0.8)),
        ],
    )


def thesis_joints() -> tuple[Joint, Joint]:
    """Spindle-holder (Table 2.1) and holder-tool (Table 2.2) joints; both warn (non-PSD)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NonPassiveJointWarning)
        k1, c1 = thesis_joint("2.1")
        k2, c2 = thesis_joint("2.2")
        return (
            Joint("spindle-holder", ("spindle.tip", "holder.base"), k=k1, c=c1),
            Joint("holder-tool", ("holder.tip", "tool.base"), k=k2, c=c2),
        )


def make_assembly(overhang_mm: float = 60.0) -> Assembly:
    sh, ht = thesis_joints()
    return Assembly(
        "thesis analytical case",
        components=(make_spindle(), make_holder(), make_tool(overhang_mm)),
        joints=(sh, ht),
    )


@pytest.fixture
def grid() -> Frequency:
    return Frequency.from_range("20 Hz", "5000 Hz", "5 Hz")


@pytest.fixture
def assembly() -> Assembly:
    return make_assembly()


def rel_err(a, b) -> float:
    """max |a - b| / max |b| (normwise relative error)."""
    a, b = np.asarray(a), np.asarray(b)
    return float(np.abs(a - b).max() / np.abs(b).max())


@pytest.fixture(autouse=True)
def _restore_registries():
    """Registrations made by a test (effects, component types) do not outlive it."""
    from substructure.components import COMPONENT_TYPES
    from substructure.diagnose.effects import EFFECTS

    saved = dict(EFFECTS), dict(COMPONENT_TYPES)
    yield
    for registry, before in zip((EFFECTS, COMPONENT_TYPES), saved):
        registry.clear()
        registry.update(before)
