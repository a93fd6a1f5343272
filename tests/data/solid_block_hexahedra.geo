// The solid block of solid_block.geo meshed with hexahedra: a transfinite, recombined volume
// (the same number of elements, about 0.6 / h, along every edge).
DefineConstant[ h = 0.2 ];
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 0.6, 0.4};
Transfinite Curve{:} = Ceil(0.6 / h) + 1;
Transfinite Surface{:};
Transfinite Volume{1};
Recombine Surface{:};
Recombine Volume{1};
Physical Volume("block") = {1};
Physical Surface("left") = {1};
Physical Surface("right") = {2};
Physical Surface("front") = {3};
Physical Surface("back") = {4};
Physical Surface("bottom") = {5};
Physical Surface("top") = {6};
