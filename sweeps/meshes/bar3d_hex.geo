// The 3D bar of paper 002 / contract §1.2 (bar3d): [0, 0.1]^2 x [0, 1] as N x N x M structured
// hexahedra, the same nodes and Q1 elements as bar3d's box at h = 0.1/N = 1/M (N = 2, M = 20:
// h = 0.05), in Gmsh's numbering. Built by extrusion with layers, as bar2d_quad.geo and for
// its reason (node k of a layered extrusion is at k/M of it: the box's lattice to ~1e-17).
// contact = bottom z = 0, clamped = top z = 1, body.
N = 2;
M = 20;
Point(1) = {0, 0, 0};
edge[] = Extrude {0.1, 0, 0} { Point{1}; Layers{N}; };
// edge[1] = the line along x.
bottom[] = Extrude {0, 0.1, 0} { Curve{edge[1]}; Layers{N}; Recombine; };
// bottom[1] = the bottom square.
body[] = Extrude {0, 0, 1} { Surface{bottom[1]}; Layers{M}; Recombine; };
// body[0] = top square, body[1] = the volume.
Physical Surface("contact") = {bottom[1]};
Physical Surface("clamped") = {body[0]};
Physical Volume("body") = {body[1]};
