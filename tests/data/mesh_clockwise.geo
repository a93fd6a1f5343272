// A triangle-shaped domain whose curve loop runs clockwise, so Gmsh produces
// clockwise elements: the reader must reorder them. Area 1.5.
DefineConstant[ h = 0.4 ];
Point(1) = {0, 0, 0, h};
Point(2) = {0, 1.5, 0, h};
Point(3) = {2, 0, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 1};
Curve Loop(1) = {1, 2, 3};
Plane Surface(1) = {1};
Physical Curve("boundary") = {1, 2, 3};
Physical Surface("body") = {1};
