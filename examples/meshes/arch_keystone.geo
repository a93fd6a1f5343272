// The keystone of the arch (examples/arch.toml): a trapezoid wedged between the abutments'
// inclined faces, with no support of its own: contact alone holds it (a floating body).
// Corners (1.5, 1), (2.5, 1), (2.8, 2), (1.2, 2).
// Boundaries: left and right (the inclined contact faces), top (y = 2, under the platen),
// bottom (y = 1, free).
DefineConstant[ h = 0.07 ];
Point(1) = {1.5, 1, 0, h};
Point(2) = {2.5, 1, 0, h};
Point(3) = {2.8, 2, 0, h};
Point(4) = {1.2, 2, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
Physical Surface("keystone") = {1};
