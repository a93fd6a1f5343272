// Upper block [0, 1] x [0, 1] x [0, 0.4] in 8-node hexahedra: a transfinite, recombined volume
// with Round(1 / h) cells along every edge. Its bottom face z = 0 is the contact boundary,
// meshed independently of the lower block (solid_patch_lower.geo, tetrahedra).
DefineConstant[ h = 0.15 ];
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 0.4};
Transfinite Curve{:} = Round(1 / h) + 1;
Transfinite Surface{:};
Transfinite Volume{1};
Recombine Surface{:};
Recombine Volume{1};
Physical Volume("block") = {1};
// OpenCASCADE's box faces: 1 x = 0, 2 x = 1, 3 y = 0, 4 y = 1, 5 z = 0, 6 z = 0.4.
Physical Surface("symmetry_x") = {1};
Physical Surface("side_x") = {2};
Physical Surface("symmetry_y") = {3};
Physical Surface("side_y") = {4};
Physical Surface("contact") = {5};
Physical Surface("top") = {6};
