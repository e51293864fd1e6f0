"""The fibres: finite-strain beams with deformable sections.

- :mod:`.material`: :class:`Material`, a fibre's elastic constants;
- :mod:`.element`: :class:`BeamElement`, the element's options;
- :mod:`.fibre`: :class:`Fibre` (a centreline, its section and material),
  :func:`straight_fibre`, :func:`arc_fibre`;
- :mod:`.fibre_mesh`: the fibres' nodes and unknowns (:class:`FibreMesh`);
- :mod:`.fibre_loads`: the loads along the fibres (axial force, moments,
  curvatures) and their maxima, from a solved model.

The physics (residual, tangent) is the effect
:class:`textile.effects.BeamElasticity` over the C++ beam kernels.
"""
from .element import BeamElement
from .fibre import Fibre, arc_fibre, straight_fibre
from .fibre_mesh import FibreMesh
from .material import Material

__all__ = ["BeamElement", "Fibre", "FibreMesh", "Material", "arc_fibre", "straight_fibre"]
