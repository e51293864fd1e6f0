"""Textile composites: a woven fabric in a matrix.

- :mod:`.matrix_mesh`: the matrix's tetrahedral mesh (:class:`MatrixMesh`:
  a gmsh box, a box around the fibres, a ``.msh`` file);
- :mod:`.composite`: :class:`Composite`, a :class:`~textile.fabric.Sample`
  with the matrix around its fibres and the fibre-matrix junctions.

The physics are effects: :mod:`textile.effects.elastic_block` (the
matrix), :mod:`textile.effects.fibre_matrix_junction` (the junctions) and
:mod:`textile.effects.rigid_bodies` (side bodies, holding the matrix's
nodes named by :class:`textile.scene.block_nodes.BlockNodes`). A scene of fibres
alone imports nothing of this package (no gmsh, no dolfinx).

:class:`Composite` is imported on first use (``from textile.composite
import Composite``): the matrix effect imports this package's mesh, and
:mod:`.composite` imports the matrix effect.
"""
from .matrix_mesh import MatrixMesh, gmsh_box

__all__ = ["Composite", "MatrixMesh", "gmsh_box"]


def __getattr__(name: str):
    if name == "Composite":
        from .composite import Composite
        return Composite
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
