// The 2D bar of paper 002 / contract §1.2 (bar2d) meshed with triangles: [0, 0.1] x [0, 1] as
// N x M squares of side 0.1/N = 1/M, each cut into two triangles (transfinite, Gmsh's "Left"
// diagonal), so the nodes at degree 1 are those of bar2d's box at h = 0.1/N but the elements
// are not: the runs on it are measured against a bar2d reference by interpolation (contract §1.6).
// h (the longest edge) = sqrt(2)·0.1/N. contact = bottom y = 0, clamped = top y = 1, body.
// generate.sh overrides N and M (N = 2, 4, 8 with M = 10 N: bar2d_tri_n*.msh).
N = 2;
M = 20;
Point(1) = {0, 0, 0};
Point(2) = {0.1, 0, 0};
Point(3) = {0.1, 1, 0};
Point(4) = {0, 1, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve {1, 3} = N + 1;
Transfinite Curve {2, 4} = M + 1;
Transfinite Surface {1};
Physical Curve("contact") = {1};
Physical Curve("clamped") = {3};
Physical Surface("body") = {1};
