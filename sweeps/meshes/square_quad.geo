// Unit square [0,1]^2 as N x M transfinite quadrilaterals (recombined): N M quads,
// (N+1)(M+1) nodes at degree 1, (2N+1)(2M+1) at degree 2 (9-node); h = sqrt(1/N^2 + 1/M^2).
// Physical groups: contact = bottom y = 0 (N lines), clamped = top y = 1 (N lines), body.
N = 4;
M = 2;
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
Transfinite Curve {1, 3} = N + 1;
Transfinite Curve {2, 4} = M + 1;
Transfinite Surface {1};
Recombine Surface {1};
Physical Curve("contact") = {1};
Physical Curve("clamped") = {3};
Physical Surface("body") = {1};
