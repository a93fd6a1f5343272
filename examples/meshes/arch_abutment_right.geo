// The right abutment of the keystone arch (examples/arch.toml), the mirror image of the left
// one about x = 2. Corners (2.5, 0), (4, 0), (4, 2), (2.8, 2), (2.5, 1).
// Boundaries: bottom (y = 0, clamped), face (the inclined contact face from (2.8, 2) to
// (2.5, 1)), free (every other side).
DefineConstant[ h = 0.1 ];
Point(1) = {2.5, 0, 0, h};
Point(2) = {4, 0, 0, h};
Point(3) = {4, 2, 0, h};
Point(4) = {2.8, 2, 0, h};
Point(5) = {2.5, 1, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 1};
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};
Physical Curve("bottom") = {1};
Physical Curve("face") = {4};
Physical Curve("free") = {2, 3, 5};
Physical Surface("abutment") = {1};
