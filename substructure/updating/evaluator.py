"""The fast evaluation of the SI form: receptances between fixed points on fixed lines, for model updating.

:class:`Evaluator` computes the receptances between fixed outputs and
inputs on fixed frequency lines for any :class:`~substructure.updating.structure.Structure`
of the same assembly: the receptances of components that did not change are
reused (identified by the arrays object they hold), the others are computed
by :func:`substructure.beams.stepped_beam_receptance_si`, and the coupling
runs in the engine of :mod:`substructure.coupling`, its steps reused where a
change did not touch them.  Components that are not plain stepped beams
(measured components, subassemblies, subclasses with their own receptances)
take part unchanged through their own ``receptance_matrix``.
"""

from __future__ import annotations

from collections import OrderedDict
from typing import Sequence

import numpy as np

from .._memo import Recent, Same
from ..beams import stepped_beam_receptances_si
from ..components import receptances
from ..coupling import Link, couple_substructures
from ..errors import AssemblyError, InvalidValueError
from ..points import DOFS
from ..units import whole_number
from .structure import LinkSI, Structure, _at, _parse

__all__ = ["Evaluator"]

LAYOUTS_KEPT = 16
"""How many layouts of structures (their nodes and links) an evaluator keeps."""


def _link_token(link: "LinkSI"):
    """What a link's dynamic stiffness is computed from (None for a joint model of its own)."""
    if link.custom is not None:
        return None
    return (link.rigid, link.K.tobytes(), link.C.tobytes(), link.M.tobytes())


def _check_structure(structure) -> None:
    if not isinstance(structure, Structure):
        raise InvalidValueError(f"structure: got {type(structure).__name__}; expected a Structure "
                                "(Structure.from_assembly(assembly))")


class Evaluator:
    """Receptances between fixed points on fixed lines, for structures of one assembly.

    Parameters
    ----------
    outputs, inputs : sequence of str
        DOF labels (``"tool.tip:y"``); a label without a DOF stands for ``y``.
    frequency_hz : ndarray
        The frequency lines [Hz].
    cache : int
        How many changed component receptances to keep (besides those of
        the first structure evaluated, which are always kept).
    memo_bytes : int
        Most bytes of coupled clusters and links' dynamic stiffnesses kept
        from earlier evaluations: a coupling step whose inputs are those of
        an earlier one (the components and links a change did not touch) is
        not computed again.
    decay : float
        ``1/tau`` [1/s]: the receptances at the complex frequency
        ``omega - i decay``, as a tap test processed through an exponential
        window ``exp(-t/tau)`` sees the structure (default 0: the real
        lines).  Every component and joint model of the structures must
        then take ``decay`` (:meth:`Structure.not_at_complex_frequency
        <substructure.updating.structure.Structure.not_at_complex_frequency>` names those that do not).

    Raises
    ------
    InvalidValueError
        Where it is made: outputs or inputs that are not a non-empty
        sequence of labels, lines that are not finite numbers above 0 Hz in
        a 1-D array (texts and booleans refused), a negative ``cache`` or
        ``memo_bytes``; when called: anything but a :class:`Structure`.
    """

    def __init__(self, outputs: Sequence[str], inputs: Sequence[str], frequency_hz: np.ndarray, cache: int = 12,
                 memo_bytes: int = 32 * 2**20, decay: float = 0.0):
        for name, labels in (("outputs", outputs), ("inputs", inputs)):
            if isinstance(labels, str) or not all(isinstance(x, str) for x in labels) or not len(labels):
                raise InvalidValueError(f"{name}: got {labels!r}; expected a sequence of DOF labels such as "
                                        "['tool.tip:y']")
        self.outputs = tuple(outputs)
        self.inputs = tuple(inputs)
        raw = np.asarray(frequency_hz)
        listed = raw.dtype.kind == "O" or not isinstance(frequency_hz, np.ndarray)  # numpy reads True as 1.0
        if raw.dtype.kind in "USb" or (listed and any(isinstance(x, (str, bytes, bool, np.bool_))
                                                      for x in np.ravel(np.asarray(frequency_hz, dtype=object)))):
            raise InvalidValueError(f"frequency_hz: got {frequency_hz!r}; expected numbers in Hz, not texts or "
                                    "booleans")
        self.f = np.asarray(raw, dtype=float)
        self.decay = float(decay)
        if self.f.ndim != 1:
            raise InvalidValueError(f"frequency_hz: got an array of shape {self.f.shape}; expected one line after "
                                    "another (1-D)")
        if self.f.size == 0 or not np.all(self.f > 0) or not np.all(np.isfinite(self.f)):
            raise InvalidValueError("frequency: a model evaluation needs lines above 0 Hz, each finite (free-free "
                                    "components have no static receptance); crop the data, e.g. from 1 Hz")
        whole_number(cache, "cache")
        whole_number(memo_bytes, "memo_bytes")
        refs = [_parse(p) for p in self.outputs + self.inputs]
        # the outputs' points, then the inputs' (a point both measured and hit is twice: the hammer may have hit
        # it elsewhere than the sensor sat, Structure.with_hit; where it did not, both are one node)
        out_points = list(dict.fromkeys(str(r.point) for r in refs[: len(self.outputs)]))
        in_points = list(dict.fromkeys(str(r.point) for r in refs[len(self.outputs):]))
        self._points = [(p, False) for p in out_points] + [(p, True) for p in in_points]
        self._dofs = [(out_points.index(str(r.point)) if i < len(self.outputs)
                       else len(out_points) + in_points.index(str(r.point)), DOFS.index(r.dof or "y"))
                      for i, r in enumerate(refs)]
        self._n_out = len(self.outputs)
        # the engine's rows and columns of the outputs and inputs (DOF indices over the points)
        self._wanted = ([2 * p + d for p, d in self._dofs[: self._n_out]],
                        [2 * p + d for p, d in self._dofs[self._n_out:]])
        self._pinned: dict = {}
        self._lru: OrderedDict = OrderedDict()
        self._size = cache
        self._memo = Recent(memo_bytes)
        self._stiffness = Recent(memo_bytes // 8)
        self._layouts: OrderedDict = OrderedDict()

    def _store(self, key, compute, pin: bool):
        if key in self._pinned:
            return self._pinned[key]
        if key in self._lru:
            self._lru.move_to_end(key)
            return self._lru[key]
        y = compute()
        if pin:
            self._pinned[key] = y
        else:
            self._lru[key] = y
            while len(self._lru) > self._size:
                self._lru.popitem(last=False)
        return y

    def _receptance(self, structure: Structure, name: str, nodes: list, pin: bool,
                    ready: dict | None = None) -> tuple[np.ndarray, object]:
        """A component's receptances at the nodes, and what identifies them (for the coupling's memo);
        ``ready``: beams' receptances computed already (:meth:`_beams_together`), by the same key."""
        if name in structure.beams:
            beam = structure.beams[name]
            xs = [x for x, _ in nodes]
            key = (beam.token, tuple(xs))  # a token is never reused
            if ready and key in ready:
                return self._store(key, lambda: ready[key], pin), key
            return self._store(key, lambda: beam.receptance(xs, self.f, self.decay), pin), key
        comp = structure.opaque[name]
        refs = [r if r is not None else _at(name, x, comp.length_m) for x, r in nodes]
        # keyed by the object's id, stored with the object itself so that the id cannot be reused while cached;
        # pinned only for the first structure (a component changed by a fit is rebuilt at every evaluation)
        key = (id(comp), tuple(str(r) for r in refs))
        kept = self._store(key, lambda: (comp, receptances(comp, refs, self.f, self.decay)), pin)
        return kept[1], (Same(comp), key[1])

    def _dynamic_stiffness(self, link: "LinkSI", token) -> np.ndarray | None:
        if token is None or link.rigid:
            return link.dynamic_stiffness(self.f, self.decay)
        found = self._stiffness.get(token)
        if found is None:
            found = link.dynamic_stiffness(self.f, self.decay)
            self._stiffness[token] = found
        return found

    def __call__(self, structure: Structure) -> np.ndarray:
        """The receptances ``(n_freq, n_out, n_in)`` of ``structure``."""
        _check_structure(structure)
        blocks, coupling, out_keys, tokens = self._prepare(structure)
        return self._pick(couple_substructures(blocks, coupling, out_keys, self._memo, tokens, pick=self._wanted))

    def many(self, structures: Sequence[Structure]) -> list[np.ndarray]:
        """The receptances of several structures, each as calling the evaluator with it gives them (the same numbers).

        Structures whose points and links sit at the same places (the trials
        of a scan that change sizes, not places) are coupled together: their
        lines side by side in one call of the engine, which treats every
        line alike.

        Parameters
        ----------
        structures : sequence of Structure
            Structures of this evaluator's assembly.

        Returns
        -------
        list of ndarray
            ``(n_freq, n_out, n_in)`` per structure, in order.
        """
        for s in structures:
            _check_structure(s)
        layouts = [self._layout(s) for s in structures]
        ready = self._beams_together(structures, layouts)
        prepared = [self._prepare(s, layout, ready) for s, layout in zip(structures, layouts)]
        groups: dict = {}
        for i, (blocks, coupling, out_keys, _) in enumerate(prepared):
            layout = (tuple(tuple(keys) for keys, _ in blocks),
                      tuple((c.a, c.b, c.stiffness is None) for c in coupling), tuple(out_keys))
            groups.setdefault(layout, []).append(i)
        out: list = [None] * len(prepared)
        n = self.f.size
        for members in groups.values():
            if len(members) == 1:
                blocks, coupling, out_keys, tokens = prepared[members[0]]
                out[members[0]] = self._pick(couple_substructures(blocks, coupling, out_keys, self._memo, tokens,
                                                                  pick=self._wanted))
                continue
            first = prepared[members[0]]
            # a block or link the same in every structure (by its token) is given once: the steps of only such
            # are computed once (and reused as in single evaluations), the others for every structure
            blocks, block_tokens = [], []
            for b, (keys, y) in enumerate(first[0]):
                token = first[3][0][b]
                if all(prepared[i][3][0][b] == token for i in members):
                    blocks.append((keys, y))
                    block_tokens.append(token)
                else:
                    blocks.append((keys, np.concatenate([prepared[i][0][b][1] for i in members], axis=-1)))
                    block_tokens.append(None)
            coupling, link_tokens = [], []
            for k, c in enumerate(first[1]):
                token = first[3][1][k]
                if c.stiffness is None or (token is not None and all(prepared[i][3][1][k] == token for i in members)):
                    coupling.append(c)
                    link_tokens.append(token)
                else:
                    coupling.append(Link(c.a, c.b, np.concatenate(
                        [np.broadcast_to(prepared[i][1][k].stiffness, (2, 2, n)) for i in members], axis=-1), c.label))
                    link_tokens.append(None)
            y = couple_substructures(blocks, coupling, first[2], self._memo, (block_tokens, link_tokens),
                                     copies=len(members), lines=n, pick=self._wanted)
            for j, i in enumerate(members):
                out[i] = self._pick(y[..., j * n:(j + 1) * n])
        return out

    def _layout(self, structure: Structure) -> tuple[dict, list, list]:
        """Where the outputs and links of a structure sit: each component's nodes, the output nodes, the links
        ``(node a, node b, link)``.

        Kept for structures whose links join the same points, whose beams have the same lengths and whose other
        components are the same objects (the trials of a scan that change sizes and values, not places): their
        nodes are the same."""
        opaque = tuple(structure.opaque.values())
        key = (tuple((link.a, link.b) for link in structure.links),
               tuple((name, beam.total_length) for name, beam in structure.beams.items()),
               tuple(id(c) for c in opaque), tuple(structure.moved.items()), tuple(structure.hits.items()))
        found = self._layouts.get(key)
        if found is not None and all(a is b for a, b in zip(found[0], opaque)):  # kept with it: ids not reused
            self._layouts.move_to_end(key)
            nodes, out_keys, pairs = found[1]
        else:
            nodes, out_keys, pairs = self._new_layout(structure)
            self._layouts[key] = (opaque, (nodes, out_keys, pairs))
            while len(self._layouts) > LAYOUTS_KEPT:
                self._layouts.popitem(last=False)
        return nodes, out_keys, [(ka, kb, link) for (ka, kb), link in zip(pairs, structure.links)]

    def _new_layout(self, structure: Structure) -> tuple[dict, list, list]:
        """:meth:`_layout` computed: the nodes, the output nodes and each link's two nodes."""
        nodes: dict[str, dict] = {}
        keys = {}

        def node(point, hit=False):
            if not isinstance(point, tuple) and (point, hit) in keys:
                return keys[(point, hit)]
            comp, x = structure.hit_position(point) if hit else structure.position(point)
            if x is None:
                ref = _parse(point).point
                owner = structure.opaque[comp]
                k = (comp, owner.node_key(ref))
                nodes.setdefault(comp, {}).setdefault(k, (None, ref))
            else:
                k = (comp, round(x, 12))
                nodes.setdefault(comp, {}).setdefault(k, (x, None))
            if not isinstance(point, tuple):
                keys[(point, hit)] = k
            return k

        out_keys = [node(p, hit) for p, hit in self._points]
        pairs = []
        for link in structure.links:
            ka = node(link.a)
            kb = None if link.b is None else node(link.b)
            if ka == kb:
                raise AssemblyError(f"{link.key[0][:-1]} {link.key[1]!r} connects a point to itself")
            pairs.append((ka, kb))
        for comp, at in nodes.items():  # the order the engine takes them in: along the component, then the others
            nodes[comp] = sorted(at.items(), key=lambda kv: (kv[1][0] is None, kv[1][0] or 0.0, str(kv[0])))
        return nodes, out_keys, pairs

    def _beams_together(self, structures: Sequence[Structure], layouts: list) -> dict:
        """The receptances of the beams that several structures hold changed alike (the same segment lengths and
        nodes, other sections: the trials of a scan, a Jacobian's steps), each group in one kernel call
        (``beams.stepped_beam_receptances_si``: the same numbers as one by one); by ``_receptance``'s key."""
        groups: dict = {}
        for structure, (nodes, _, _) in zip(structures, layouts):
            for comp, items in nodes.items():
                beam = structure.beams.get(comp)
                if beam is None or beam.has_taper:  # a taper's pieces follow the nodes: one by one
                    continue
                xs = tuple(x for _, (x, _) in items)
                key = (beam.token, xs)
                if key in self._pinned or key in self._lru:
                    continue
                groups.setdefault((comp, xs, beam.length.tobytes()), {})[key] = beam
        ready: dict = {}
        for (_, xs, _), members in groups.items():
            if len(members) < 2:
                continue
            beams = list(members.values())
            ys = stepped_beam_receptances_si([b.sections() for b in beams], beams[0].length, xs, self.f, self.decay)
            if ys is not None:
                ready.update(zip(members, (np.ascontiguousarray(y) for y in ys)))
        return ready

    def _prepare(self, structure: Structure, layout: tuple | None = None, ready: dict | None = None):
        """The blocks, links, output points and memo tokens of one structure, for the engine."""
        pin = not self._pinned  # the first structure's components are kept for good
        nodes, out_keys, links = layout if layout is not None else self._layout(structure)
        blocks, block_tokens = [], []
        for comp in structure.order:
            if comp not in nodes:
                continue
            items = nodes[comp]
            y, token = self._receptance(structure, comp, [v for _, v in items], pin, ready)
            blocks.append(([k for k, _ in items], y))
            block_tokens.append(token)
        link_tokens = [_link_token(link) for _, _, link in links]
        coupling = [Link(ka, kb, self._dynamic_stiffness(link, token), f"{link.key[0][:-1]} {link.key[1]!r}")
                    for (ka, kb, link), token in zip(links, link_tokens)]
        return blocks, coupling, out_keys, (block_tokens, link_tokens)

    @staticmethod
    def _pick(y: np.ndarray) -> np.ndarray:
        """The engine's result (the outputs' and inputs' entries, ``pick``), frequency first."""
        return y.transpose((y.ndim - 1,) + tuple(range(y.ndim - 1)))  # np.moveaxis(y, -1, 0), for less
