// A half cylinder of radius 1: the lower half of the disk centred at (0, 1). Its curved boundary
// is the contact boundary where |x| <= 0.4 ("contact", refined to h / 20), and free elsewhere
// ("side"); the flat top y = 1 is loaded ("top").
// h: coarse element size (mesh_size in the case file).
DefineConstant[ h = 0.1 ];
fine = h / 20;
c = 0.4;                     // half-width of the contact arc
s = Sqrt(1 - c * c);         // its end points are (+-c, 1 - s)

Point(1) = {0, 1, 0, h};     // the centre
Point(2) = {-1, 1, 0, h};
Point(3) = {-c, 1 - s, 0, fine};
Point(4) = {0, 0, 0, fine};
Point(5) = {c, 1 - s, 0, fine};
Point(6) = {1, 1, 0, h};
Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 4};
Circle(3) = {4, 1, 5};
Circle(4) = {5, 1, 6};
Line(5) = {6, 2};
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};

Physical Curve("contact") = {2, 3};
Physical Curve("side") = {1, 4};
Physical Curve("top") = {5};
Physical Surface("cylinder") = {1};
