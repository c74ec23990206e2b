"""Sweeps: the same receptance for many variants of an assembly, vectorised.

A sweep (tool overhangs, joint stiffnesses, sensor masses, ...) is a list of
assemblies with the same structure: the same components, joints, sensors and
supports by name, differing in geometry and values.  :func:`sweep` evaluates
them together: whatever is the same in every variant (usually the spindle and
holder) is computed once, beams that differ are evaluated in one batched call,
and the coupling engine runs once over an axis that holds every variant's
frequency lines.

Examples
--------
>>> from substructure import Tool, Segment
>>> from substructure.io.assembly_toml import default_assembly
>>> base = default_assembly()                                  # doctest: +SKIP
>>> variants = [base.with_component(Tool.end_mill("12 mm", f"{L} mm", "30 mm"))
...             for L in range(40, 90, 5)]                       # doctest: +SKIP
>>> result = sweep(variants, "tool.tip:y")                      # doctest: +SKIP
>>> result.data.shape                                          # doctest: +SKIP
(10, 2491, 1, 1)
"""

from __future__ import annotations

import sys
from typing import Sequence

import attrs
import numpy as np

from .assembly import Assembly, expand_points
from .beams import stepped_beam_receptance_batch
from .components import is_plain_beam, receptances
from .components.beam import check_reach
from .coupling import Link, couple_substructures
from .errors import InvalidValueError
from .frf import FRF, Frequency
from .joints import dynamic_stiffness
from .units import items_of, whole_number

# MAX_SWEEP_VALUES is not listed: the module shares the sweep function's name in the API pages
__all__ = ["SweepResult", "sweep"]

MAX_SWEEP_VALUES = 100_000_000
"""The most receptance values a sweep returns (1.6 GB of complex numbers), checked before any work."""


def _show(value) -> str:
    text = repr(value)
    return f"an object of type {type(value).__name__}" if len(text) > 80 else text


@attrs.frozen
class SweepResult:
    """Receptances of every variant of a sweep.

    Parameters
    ----------
    frequency : Frequency
        The frequency lines, in Hz.
    data : ndarray, shape (n_variants, n_freq, n_out, n_in)
        Complex receptances of every variant (m/N, m/(N m), rad/N, rad/(N m)).
    outputs : tuple of str
        Output DOF labels (``"tool.tip:y"``).
    inputs : tuple of str
        Input DOF labels.
    """

    frequency: Frequency
    data: np.ndarray = attrs.field(eq=attrs.cmp_using(eq=np.array_equal))
    outputs: tuple[str, ...]
    inputs: tuple[str, ...]

    def __len__(self) -> int:
        return self.data.shape[0]

    def __getitem__(self, i: int) -> FRF:
        """The FRF of variant ``i``."""
        return FRF(self.frequency, self.data[i], self.outputs, self.inputs)


def _same(items) -> bool:
    first = items[0]
    return all(x is first or x == first for x in items[1:])


def _check_structure(plans, assemblies) -> None:
    ref_groups, ref_out, ref_links = plans[0]
    for i, (groups, out, links) in enumerate(plans[1:], start=1):
        same = len(groups) == len(ref_groups) and len(links) == len(ref_links)
        same = same and all(
            g[0].name == r[0].name and [str(p) for _, p in g[1]] == [str(p) for _, p in r[1]]
            for g, r in zip(groups, ref_groups)
        )
        same = same and all(k[3] == r[3] for k, r in zip(links, ref_links))
        if not same:
            raise InvalidValueError(
                f"sweep: variant {i} ({assemblies[i].name!r}) has another structure than variant 0; "
                "a sweep needs the same components, joints, sensors and supports by name"
            )
        # the links are coupled at variant 0's nodes: a sensor moved to another point that takes part anyway
        # (an output) has the same nodes and names, and was computed where variant 0 has it
        for link, ref in zip(links, ref_links):
            ends, ref_ends = _ends(link, groups), _ends(ref, ref_groups)
            if sorted(ends) != sorted(ref_ends):  # a joint's two ends in either order: B and -B couple alike
                raise InvalidValueError(
                    f"sweep: variant {i} ({assemblies[i].name!r}) has {link[3]} at {' -- '.join(ends)}, variant 0 "
                    f"at {' -- '.join(ref_ends)}; a sweep needs each joint, sensor, mass and support at the same "
                    "points in every variant (compute variants that move one with Assembly.frf, one by one)"
                )


def _ends(link, groups) -> tuple[str, ...]:
    """The point names of a link's ends in its plan."""
    names = {k: str(p) for _, items in groups for k, p in items}
    return tuple(names[k] for k in link[:2] if k is not None)


def sweep(
    assemblies: Sequence[Assembly],
    outputs: Sequence[str] | str,
    inputs: Sequence[str] | str | None = None,
    frequency=None,
    *,
    chunk_lines: int = 50_000,
    progress: bool = False,
) -> SweepResult:
    """Receptances from ``inputs`` to ``outputs`` for every assembly of a sweep.

    Parameters
    ----------
    assemblies : sequence of Assembly
        The variants, all of the same structure.
    outputs, inputs : str or sequence of str
        Point names as for :meth:`Assembly.frf`.
    frequency : Frequency or array of Hz, optional
        Defaults to the first assembly's grid.
    chunk_lines : int
        Variants are evaluated in chunks of about this many frequency lines
        in all (bounds the memory: about 0.5 kB per line for a tool of two
        points, so 25 MB at the default).
    progress : bool
        Print the progress to standard error (a line per percent at most).

    Returns
    -------
    SweepResult
        The receptances of every variant, shape ``(n_variants, n_freq, n_out, n_in)``
        (m/N, m/(N m), rad/N, rad/(N m)).
    """
    if isinstance(assemblies, Assembly):
        raise InvalidValueError(f"sweep: got {_show(assemblies)}; expected a sequence of assemblies (a list: "
                                "[assembly] for one)")
    assemblies = items_of(assemblies, "sweep", "assemblies (a list: [assembly] for one)")
    if not assemblies:
        raise InvalidValueError("sweep: got no assemblies")
    for i, a in enumerate(assemblies):
        if not isinstance(a, Assembly):
            raise InvalidValueError(f"sweep: variant {i} is {_show(a)}; expected an Assembly")
    whole_number(chunk_lines, "chunk_lines", 1, "a whole number of lines")
    freq = assemblies[0]._frequency(frequency)
    f = freq.hz
    n_f = f.size
    out_labels, out_idx, out_refs = expand_points(outputs)
    in_labels, in_idx, in_refs = expand_points(outputs if inputs is None else inputs)
    values = len(assemblies) * n_f * len(out_labels) * len(in_labels)
    if values > MAX_SWEEP_VALUES:
        raise InvalidValueError(
            f"sweep: {len(assemblies)} variants x {n_f} lines x {len(out_labels)} x {len(in_labels)} DOFs would be "
            f"{values:.3g} complex values ({values * 16 / 1e9:.3g} GB), more than {MAX_SWEEP_VALUES:.0e} "
            "(sweep.MAX_SWEEP_VALUES): sweep fewer variants at a time, over fewer lines or DOFs, or run a study "
            "(substructure study), which saves each result as it is computed"
        )
    refs = out_refs + in_refs
    plans = [a._plan(refs) for a in assemblies]
    _check_structure(plans, assemblies)
    # canonical keys: (group, item) for nodes; outputs mapped through variant 0
    key_of = [{k: (gi, ii) for gi, (_, items) in enumerate(groups) for ii, (k, _) in enumerate(items)}
              for groups, _, _ in plans]
    groups0, out0, links0 = plans[0]
    out_keys = [key_of[0][k] for k in out0]
    rows = [2 * i + d for i, d in out_idx]
    cols = [2 * (len(out_refs) + i) + d for i, d in in_idx]

    n_var = len(assemblies)
    owners_of = [[plans[c][0][gi][0] for c in range(n_var)] for gi in range(len(groups0))]
    objs_of = [[plans[c][2][li][2] for c in range(n_var)] for li in range(len(links0))]
    refs0 = [[r for _, r in items] for _, items in groups0]
    const_groups = {gi for gi in range(len(groups0)) if _same(owners_of[gi])}

    def canonical_link(li: int, stiffness) -> Link:
        ka, kb, _, label = links0[li]
        return Link(key_of[0][ka], None if kb is None else key_of[0][kb], stiffness, label)

    def node_group(key) -> int:
        return key_of[0][key][0]

    # Stage 1: couple what every variant shares (e.g. spindle and holder) once,
    # keeping only the points the rest of the coupling needs.
    const_links = [
        li for li, (ka, kb, obj, _) in enumerate(links0)
        if node_group(ka) in const_groups and (kb is None or node_group(kb) in const_groups)
        and _same(objs_of[li])
    ]
    later_links = [li for li in range(len(links0)) if li not in const_links]
    shared_block = None
    if const_groups:
        needed = []
        for li in later_links:
            for k in (links0[li][0], links0[li][1]):
                if k is not None and node_group(k) in const_groups and key_of[0][k] not in needed:
                    needed.append(key_of[0][k])
        for k in out_keys:
            if k[0] in const_groups and k not in needed:
                needed.append(k)
        blocks0 = [
            ([(gi, ii) for ii in range(len(refs0[gi]))], receptances(owners_of[gi][0], refs0[gi], f))
            for gi in sorted(const_groups)
        ]
        links_s = [
            canonical_link(li, None if getattr(links0[li][2], "rigid", False) else dynamic_stiffness(links0[li][2], f))
            for li in const_links
        ]
        shared_block = (needed, couple_substructures(blocks0, links_s, needed)) if needed else None

    # the batched beam kernel only for components that say they are plain stepped beams
    # (component protocol: anything else, e.g. a Beam subclass with a lumped mass in its
    # receptance_matrix, is asked for its own receptances)
    all_beams = {gi: all(is_plain_beam(o) for o in owners_of[gi]) for gi in range(len(groups0))}
    per_chunk = max(1, chunk_lines // n_f)
    data = np.empty((n_var, n_f, len(rows), len(cols)), dtype=complex)
    constant_links: dict[int, np.ndarray] = {}
    shown = -1  # the percentage last printed
    for start in range(0, n_var, per_chunk):
        chunk = range(start, min(n_var, start + per_chunk))
        n_c = len(chunk)
        blocks = []
        if shared_block is not None:
            blocks.append((shared_block[0], np.tile(shared_block[1], (1, 1, n_c))))
        for gi in range(len(groups0)):
            if gi in const_groups:
                continue
            owners = owners_of[gi]
            keys = [(gi, ii) for ii in range(len(refs0[gi]))]
            if all_beams[gi] and all(
                r.where in ("base", "tip") for r in refs0[gi]
            ) and len({len(owners[c].segments) for c in chunk}) == 1:
                for c in chunk:  # what Beam.receptance_matrix checks, for the batched kernel
                    check_reach(owners[c], f)
                y = stepped_beam_receptance_batch(
                    [owners[c].segments for c in chunk], [r.where for r in refs0[gi]], f
                )
            else:
                refs_c = [[r for _, r in plans[c][0][gi][1]] for c in chunk]
                y = np.concatenate(
                    [receptances(owners[c], rc, f) for c, rc in zip(chunk, refs_c)], axis=-1
                )
            blocks.append((keys, y))
        links = []
        for li in later_links:
            objs = objs_of[li]
            label = links0[li][3]
            rigid = [bool(getattr(o, "rigid", False)) for o in objs]
            if any(rigid) and not all(rigid):
                raise InvalidValueError(f"sweep: {label} is rigid in some variants and elastic in others")
            if rigid[0]:
                stiffness = None
            elif _same(objs):
                if li not in constant_links:
                    constant_links[li] = dynamic_stiffness(objs[0], f)
                stiffness = np.tile(constant_links[li], (1, 1, n_c))
            else:
                stiffness = np.concatenate([dynamic_stiffness(objs[c], f) for c in chunk], axis=-1)
            links.append(canonical_link(li, stiffness))
        y = couple_substructures(blocks, links, out_keys)
        y = y[np.ix_(rows, cols)].reshape(len(rows), len(cols), n_c, n_f)
        data[chunk.start : chunk.stop] = np.transpose(y, (2, 3, 0, 1))
        percent = 100 * chunk.stop // n_var
        if progress and (percent > shown or chunk.stop == n_var):  # at most 101 lines, whatever the chunks
            shown = percent
            print(f"sweep: {chunk.stop}/{n_var} variants", file=sys.stderr, flush=True)
    data.flags.writeable = False
    return SweepResult(freq, data, tuple(out_labels), tuple(in_labels))
