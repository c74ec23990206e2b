"""Components: the substructures an assembly is made of.

A component knows its points and produces its free-free receptances between
them; it knows nothing of assemblies.  Three kinds ship with the package:

* :class:`Beam` and its kinds :class:`Spindle`, :class:`Holder`,
  :class:`Tool`: stepped Timoshenko beams from :mod:`substructure.beams`;
* :class:`MeasuredComponent`: receptances given as data (a tap test, or a
  computed subassembly), at the points its FRF names;
* :class:`substructure.assembly.Assembly` itself, so that a subassembly can be
  coupled like any other component (thesis eq. 2.2).

The protocol a component satisfies (duck-typed, nothing to inherit):

``name``
    Its name.
``component_names``
    The component names whose points it answers for (its own name; all
    inner names for a subassembly).
``node_key(ref) -> hashable``
    A key identifying the physical point of a :class:`~substructure.points.PointRef`
    (two names of the same place give the same key); raises
    :class:`~substructure.errors.UnknownPointError` for a point it lacks.
``receptance_matrix(refs, frequency_hz) -> ndarray``
    The receptances between the points, shape ``(2p, 2p, n_freq)``
    (frequency last), DOFs ``(y, theta)`` per point.

Two optional members: ``parameters()`` names the numbers a type adds to
its segments (a nut's mass), so that identification and the diagnosis can
fit them by path (``components.NAME.FIELD``; see :mod:`.parameters`, which
derives them from the class's own fields when the member is absent); and one
lets batched computations take a shortcut:

``plain_beam`` (bool, default False)
    True when the receptances are exactly those of the stepped beam of the
    component's ``segments`` between its ends (``base``, ``tip``): a sweep
    then evaluates many such components in one call of the beam kernel from
    their segments, without calling ``receptance_matrix``.  :class:`Beam`
    says True; a subclass that overrides ``receptance_matrix`` or
    ``position`` says False unless it sets ``plain_beam = True`` itself (see
    :func:`is_plain_beam`).

New component types are registered with :func:`register_component` so that
assembly files can name them by their ``type``.

The package holds one concept per module: ``protocol`` (the registry
``COMPONENT_TYPES``, :func:`register_component`, :func:`is_plain_beam`
and the helpers every component uses), ``beam`` (:class:`Beam`,
:class:`Spindle`, :class:`Holder`), ``tool`` (:class:`Tool` and
:meth:`Tool.end_mill`), ``measured`` (:class:`MeasuredComponent`) and
``parameters`` (:class:`ComponentParameter`, :func:`own_parameters`,
:func:`with_parameter`); every
name is imported from here.
"""

from __future__ import annotations

from .protocol import COMPONENT_TYPES, as_frequency, dof_labels, is_plain_beam, receptances, register_component

# in this order, so that COMPONENT_TYPES lists the types as it always has: beam, spindle,
# holder, tool, measured; component_info is for Assembly.describe
from .beam import Beam, Spindle, component_info  # noqa: E402, F401
from .holder import Holder  # noqa: E402
from .tool import Tool  # noqa: E402
from .measured import MeasuredComponent  # noqa: E402
from .parameters import ComponentParameter, own_parameters, with_parameter  # noqa: E402

__all__ = [
    "Beam",
    "Spindle",
    "Holder",
    "Tool",
    "MeasuredComponent",
    "COMPONENT_TYPES",
    "register_component",
    "as_frequency",
    "dof_labels",
    "is_plain_beam",
    "receptances",
    "ComponentParameter",
    "own_parameters",
    "with_parameter",
]
