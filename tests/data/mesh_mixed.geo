// Two skewed quadrilateral regions sharing a side: the right one is recombined into
// quadrilaterals, the left one stays triangular, so the mesh has mixed blocks.
DefineConstant[ h = 0.25 ];
Point(1) = {0.0, 0.0, 0, h};
Point(2) = {1.1, 0.1, 0, h};
Point(3) = {2.0, -0.1, 0, h};
Point(4) = {2.2, 1.0, 0, h};
Point(5) = {0.9, 1.2, 0, h};
Point(6) = {0.1, 0.9, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 6};
Line(6) = {6, 1};
Line(7) = {2, 5};
Curve Loop(1) = {1, 7, 5, 6};
Plane Surface(1) = {1};
Curve Loop(2) = {2, 3, 4, -7};
Plane Surface(2) = {2};
Recombine Surface{2};
Physical Curve("bottom") = {1, 2};
Physical Curve("right") = {3};
Physical Curve("top") = {4, 5};
Physical Curve("left") = {6};
Physical Surface("body") = {1, 2};
