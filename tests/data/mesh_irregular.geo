// Skewed, non-convex hexagon (a re-entrant corner at point 4) for the patch and
// manufactured-solution tests. Area 3.135 (shoelace of the points below).
DefineConstant[ h = 0.3 ];
Point(1) = {0.0, 0.0, 0, h};
Point(2) = {2.0, 0.2, 0, h};
Point(3) = {2.3, 1.1, 0, h};
Point(4) = {1.2, 0.9, 0, h};
Point(5) = {1.4, 2.0, 0, h};
Point(6) = {-0.2, 1.6, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 6};
Line(6) = {6, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6};
Plane Surface(1) = {1};
Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("notch") = {3, 4};
Physical Curve("top") = {5};
Physical Curve("left") = {6};
Physical Surface("body") = {1};
