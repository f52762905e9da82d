// Unit cube [0,1]^3 as an N x N x N transfinite grid, each cube split into 6 tetrahedra:
// 6 N^3 tetrahedra, (N+1)^3 nodes; contact = bottom z = 0 (2 N^2 triangles, (N+1)^2 nodes),
// clamped = top z = 1, body. Written binary by generate.sh (cube_tet.msh).
N = 2;
Point(1) = {0, 0, 0};
Point(2) = {1, 0, 0};
Point(3) = {1, 1, 0};
Point(4) = {0, 1, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve {1, 2, 3, 4} = N + 1;
Transfinite Surface {1};
out[] = Extrude {0, 0, 1} { Surface{1}; Layers{N}; };
// out[0] = top, out[1] = volume.
Transfinite Volume {out[1]};
Physical Surface("contact") = {1};
Physical Surface("clamped") = {out[0]};
Physical Volume("body") = {out[1]};
