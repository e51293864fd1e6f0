#!/usr/bin/env python3
"""Write a gmsh mesh (.msh) of a matrix box with named sides.

The box [corner0, corner1] is meshed with first-order tetrahedra of edge
length about --size; its six sides are physical surfaces named xmin, xmax,
ymin, ymax, zmin, zmax (tags 1-6) and its volume the physical volume
"matrix" (tag 7), as textile.composite.matrix_mesh.gmsh_box makes them. Read the
file back with textile.composite.matrix_mesh.read_msh(comm, path), or edit it in gmsh
first (the named groups are what textile reads).

    python3 meshes/matrix_box.py --corner0 0 0 0 --corner1 2 1 0.2 --size 0.1 -o box.msh

Runs serially (gmsh alone); textile must be built (bash .ci/build).
"""
import argparse
import os
import sys


def _matrix_mesh():
    """textile.composite.matrix_mesh, from this source tree when textile is not installed."""
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    from textile.composite import matrix_mesh
    return matrix_mesh


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--corner0", type=float, nargs=3, default=[0.0, 0.0, 0.0],
                        metavar=("X", "Y", "Z"), help="lowest corner (length unit)")
    parser.add_argument("--corner1", type=float, nargs=3, default=[1.0, 1.0, 0.2],
                        metavar=("X", "Y", "Z"), help="highest corner (length unit)")
    parser.add_argument("--size", type=float, default=0.1,
                        help="target tetrahedron edge length (coarse: several fibre diameters)")
    parser.add_argument("-o", "--output", default="matrix_box.msh", help="the .msh file to write")
    args = parser.parse_args(argv)
    mm = _matrix_mesh()
    with mm.gmsh_session() as gmsh:
        gmsh.model.add("matrix box")
        try:
            mm.build_gmsh_box(gmsh, args.corner0, args.corner1, args.size)
        except ValueError as e:
            parser.error(str(e))
        gmsh.write(args.output)
        tets = sum(len(t) for t in gmsh.model.mesh.getElements(3)[1])
        nodes = len(gmsh.model.mesh.getNodes()[0])
    print(f"{args.output}: {tets} tetrahedra, {nodes} nodes, sides "
          f"{', '.join(mm.SIDE_TAGS)} (tags 1-6), volume 'matrix' (tag 7)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
