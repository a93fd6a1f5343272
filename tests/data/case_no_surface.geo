// A .geo with a physical curve but no surface: the mesh reader must reject it
// (no 2D elements), and load_body must prefix the case context to its message.
DefineConstant[ h = 0.5 ];
Point(1) = {0, 0, 0, h};
Point(2) = {1, 0, 0, h};
Line(1) = {1, 2};
Physical Curve("contact") = {1};
