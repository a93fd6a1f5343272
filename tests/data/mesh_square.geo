// Unit square for the mesh reader tests. The left side is a physical curve
// without a name (tag 14), so the reader names it "14". Point 9 is a stray point
// outside the surface: its node must not appear in the mesh read from this .geo.
DefineConstant[ h = 0.5 ];
Point(1) = {0, 0, 0, h};
Point(2) = {1, 0, 0, h};
Point(3) = {1, 1, 0, h};
Point(4) = {0, 1, 0, h};
Point(9) = {3, 3, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve(14) = {4};
Physical Surface("body") = {1};
