// The platen that presses the keystone down (examples/arch.toml): [1.3, 2.7] x [2, 2.3].
// Boundaries: bottom (y = 2, on the keystone), top (y = 2.3, displacement prescribed), sides.
DefineConstant[ h = 0.05 ];
Point(1) = {1.3, 2, 0, h};
Point(2) = {2.7, 2, 0, h};
Point(3) = {2.7, 2.3, 0, h};
Point(4) = {1.3, 2.3, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Curve("bottom") = {1};
Physical Curve("top") = {3};
Physical Curve("sides") = {2, 4};
Physical Surface("platen") = {1};
