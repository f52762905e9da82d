// Unit cube [0,1]^3 as N x N x N transfinite hexahedra (recombined, extruded in N layers):
// N^3 hexahedra, (N+1)^3 nodes at degree 1, (2N+1)^3 at degree 2 (27-node); h = sqrt(3)/N.
// contact = bottom z = 0 (N^2 quadrilaterals), clamped = top z = 1, body.
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
Recombine Surface {1};
out[] = Extrude {0, 0, 1} { Surface{1}; Layers{N}; Recombine; };
Physical Surface("contact") = {1};
Physical Surface("clamped") = {out[0]};
Physical Volume("body") = {out[1]};
