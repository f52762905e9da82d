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
# The 3D bar of bar3d at h = 0.05 in hexahedra (tests/mesh_scenes.rs: Nitsche, the penalty and
# contract §3.2's methods reproduce bar3d's rows).
g bar3d_hex.geo -3 -order 1 -o bar3d_hex.msh
# The same bar at h/2 (N = 4, M = 40): a finer mesh file as the reference of bar2d_quad.msh
# (tests/mesh_scenes.rs: the interpolating path equals bar2d's node-for-node one).
bar() { # bar GEO N OUT: the 002 bar with N cells across, M = 10 N along
    local tmp
    tmp=$(mktemp --suffix .geo)
    sed -e "s/^N = .*/N = $2;/" -e "s/^M = .*/M = $(($2 * 10));/" "$1" >"$tmp"
    g "$tmp" -2 -order 1 -o "$3"
    rm -f "$tmp"
}
bar bar2d_quad.geo 4 bar2d_quad_n4.msh
# The same bar in P1 triangles at three sizes, against a bar2d reference (tests/mesh_scenes.rs,
# sweeps/bar2d_triangles.toml).
for n in 2 4 8; do
    bar bar2d_tri.geo $n bar2d_tri_n$n.msh
done
g cube_hex.geo -3 -order 1 -o cube_hex_q1.msh
g cube_hex.geo -3 -order 2 -o cube_hex_q2.msh
# The Hertz half-disc of sweeps/hertz_halfdisc.toml (P2: Mesh.ElementOrder = 2 in the .geo).
g hertz_halfdisc.geo -2 -order 2 -o hertz_halfdisc.msh
# A ball of P2 tetrahedra for mesh3d (tests/hertz.rs).
g ball_tet.geo -3 -order 2 -o ball_tet.msh
# The 003 disc in P2 triangles (tests/getfem_disc.rs: the engine against GetFEM on this file).
g disc_p2.geo -2 -order 2 -o disc_p2.msh
# Refinement families of the unit square and cube for the manufactured convergence test
# (tests/fe_convergence.rs): the same .geo files with N overridden (M = N for the quadrilaterals).
conv() { # conv GEO N DIM ORDER OUT [extra gmsh args]
    local geo=$1 n=$2 dim=$3 order=$4 out=$5
    shift 5
    local tmp
    tmp=$(mktemp --suffix .geo)
    sed -e "s/^N = .*/N = $n;/" -e "s/^M = .*/M = $n;/" "$geo" >"$tmp"
    g "$tmp" "-$dim" -order "$order" "$@" -o "conv/$out"
    rm -f "$tmp"
}
mkdir -p conv
for n in 4 8 16; do
    conv square_tri.geo $n 2 1 square_tri_p1_n$n.msh
    conv square_tri.geo $n 2 2 square_tri_p2_n$n.msh
    conv square_quad.geo $n 2 1 square_quad_q1_n$n.msh
    conv square_quad.geo $n 2 2 square_quad_q2_n$n.msh
done
# P1 simplices reach their asymptotic rate late: one more level each.
conv square_tri.geo 32 2 1 square_tri_p1_n32.msh
conv cube_tet.geo 8 3 1 cube_tet_p1_n8.msh -bin
for n in 2 3 4 6; do
    conv cube_tet.geo $n 3 1 cube_tet_p1_n$n.msh -bin
    conv cube_tet.geo $n 3 2 cube_tet_p2_n$n.msh -bin
    conv cube_hex.geo $n 3 1 cube_hex_q1_n$n.msh -bin
    conv cube_hex.geo $n 3 2 cube_hex_q2_n$n.msh -bin
done
# The sliding blocks of contract §1.8 (nothing clamped, Γ_C the bottom face; sweeps/sliding_block.toml,
# tests/sliding_block.rs).
g block2d.geo -2 -order 1 -o block2d.msh
g block3d.geo -3 -order 1 -o block3d.msh
# The frictional step's cost on a 3D block (benches/fe.rs, issue 43): 12 x 6 x 18 hexahedra,
# 13 x 7 x 19 nodes (5 187 dofs), 72 contact faces (648 Nitsche points).
tmp=$(mktemp --suffix .geo)
sed -e "s/^N = .*/N = 12;/" -e "s/^M = .*/M = 6;/" -e "s/^L = .*/L = 18;/" block3d.geo >"$tmp"
g "$tmp" -3 -order 1 -o block3d_5k.msh
rm -f "$tmp"
