// The 2D bar of paper 002 / contract §1.2 (bar2d): [0, 0.1] x [0, 1] as N x M structured
// quadrilaterals, the same nodes and Q1 elements as bar2d's box at h = 0.1/N = 1/M (N = 2,
// M = 20: h = 0.05), in Gmsh's numbering. Built by extrusion with layers (structured, as a
// transfinite surface) because extrusion places node k of a layered segment at k/M of it,
// which is the box's lattice to round-off (~1e-17), where the transfinite interpolation of a
// curve leaves ~1e-13. contact = bottom y = 0, clamped = top y = 1, body.
N = 2;
M = 20;
Point(1) = {0, 0, 0};
bottom[] = Extrude {0.1, 0, 0} { Point{1}; Layers{N}; };
// bottom[1] = the bottom line.
body[] = Extrude {0, 1, 0} { Curve{bottom[1]}; Layers{M}; Recombine; };
// body[0] = top line, body[1] = surface, body[2], body[3] = the sides.
Physical Curve("contact") = {bottom[1]};
Physical Curve("clamped") = {body[0]};
Physical Surface("body") = {body[1]};
