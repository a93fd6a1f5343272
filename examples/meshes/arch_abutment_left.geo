// The left abutment of the keystone arch (examples/arch.toml): a block with an inclined face
// on which the keystone rests. Corners (0, 0), (1.5, 0), (1.5, 1), (1.2, 2), (0, 2).
// Boundaries: bottom (y = 0, clamped), face (the inclined contact face from (1.5, 1) to
// (1.2, 2)), free (every other side).
DefineConstant[ h = 0.1 ];
Point(1) = {0, 0, 0, h};
Point(2) = {1.5, 0, 0, h};
Point(3) = {1.5, 1, 0, h};
Point(4) = {1.2, 2, 0, h};
Point(5) = {0, 2, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 1};
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};
Physical Curve("bottom") = {1};
Physical Curve("face") = {3};
Physical Curve("free") = {2, 4, 5};
Physical Surface("abutment") = {1};
