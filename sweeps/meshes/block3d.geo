// The sliding block of contract §1.8 in 3D: the box [0,1] x [0,0.5] x [0,0.5] as N x M x M
// transfinite hexahedra (the bottom face recombined, extruded in L = M layers): N M^2 hexahedra,
// (N+1)(M+1)^2 nodes at degree 1; h = sqrt(1/N^2 + 0.5/M^2). (generate.sh overrides N, M, L for
// the 5 187-dof block of benches/fe.rs.)
// Physical groups: contact = bottom z = 0 (N M quadrilaterals), body. Nothing is clamped: the
// block rests on the plane and slides on it (sweeps/sliding_block.toml, tests/sliding_block.rs).
N = 4;
M = 2;
L = M;
Point(1) = {0, 0, 0};
Point(2) = {1, 0, 0};
Point(3) = {1, 0.5, 0};
Point(4) = {0, 0.5, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve {1, 3} = N + 1;
Transfinite Curve {2, 4} = M + 1;
Transfinite Surface {1};
Recombine Surface {1};
out[] = Extrude {0, 0, 0.5} { Surface{1}; Layers{L}; Recombine; };
Physical Surface("contact") = {1};
Physical Volume("body") = {out[1]};
