// Hertz contact, Upper body [-1, 1] x [0, 1]; the curvature of the cylinder is the case's gap function x^2/(2R); bottom edge y = 0 is the contact boundary.
// h: coarse element size; the contact edge is refined to h/40 on |x| <= 0.15 (about 20 a for the
// shipped load) and h/10 beyond. All contact segments are transfinite so that both bodies have
// identical nodes on y = 0.
DefineConstant[ h = 0.1 ];
fine = h / 40;
medium = h / 10;

Point(1) = {-1, 0, 0, medium};
Point(2) = {-0.15, 0, 0, fine};
Point(3) = { 0.15, 0, 0, fine};
Point(4) = { 1, 0, 0, medium};
Point(5) = { 1, 1, 0, h};
Point(6) = {-1, 1, 0, h};
Line(1) = {1, 2};   // contact edge pieces, oriented -x to +x in both bodies
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 6};
Line(6) = {6, 1};
Transfinite Curve{1, 3} = Round(0.85 / medium) + 1;
Transfinite Curve{2} = Round(0.3 / fine) + 1;
Curve Loop(1) = {1, 2, 3, 4, 5, 6};
Plane Surface(1) = {1};

Physical Curve("contact") = {1, 2, 3};
Physical Curve("right") = {4};
Physical Curve("top") = {5};
Physical Curve("left") = {6};
Physical Surface("body") = {1};
