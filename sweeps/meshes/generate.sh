#!/usr/bin/env bash
# Regenerates the .msh test meshes from their .geo sources (MSH 4.1; the tests read the committed
# .msh files and need no Gmsh). Gmsh comes from tests/install_gmsh.sh (the `gmsh` Python wheel).
set -euo pipefail
cd "$(dirname "$0")"
../../tests/install_gmsh.sh
g() { gmsh -v 1 -format msh41 "$@"; }
g square_tri.geo -2 -order 1 -o square_tri_p1.msh
g square_tri.geo -2 -order 1 -bin -o square_tri_p1_bin.msh
g square_tri.geo -2 -order 2 -o square_tri_p2.msh
g square_quad.geo -2 -order 1 -o square_quad_q1.msh
g square_quad.geo -2 -order 2 -o square_quad_q2.msh
g cube_tet.geo -3 -order 1 -bin -o cube_tet.msh
g cube_tet.geo -3 -order 2 -o cube_tet_p2.msh
g bar2d_quad.geo -2 -order 1 -o bar2d_quad.msh
g cube_hex.geo -3 -order 1 -o cube_hex_q1.msh
g cube_hex.geo -3 -order 2 -o cube_hex_q2.msh
