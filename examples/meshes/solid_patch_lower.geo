// Lower block [0, 1] x [0, 1] x [-0.5, 0] in 4-node tetrahedra (unstructured); its top face
// z = 0 is the contact boundary. `h` is the element size: the upper block
// (solid_patch_upper.geo, hexahedra) has other nodes on the contact face.
DefineConstant[ h = 0.2 ];
SetFactory("OpenCASCADE");
Box(1) = {0, 0, -0.5, 1, 1, 0.5};
MeshSize{ PointsOf{ Volume{1}; } } = h;
Physical Volume("block") = {1};
// OpenCASCADE's box faces: 1 x = 0, 2 x = 1, 3 y = 0, 4 y = 1, 5 z = -0.5, 6 z = 0.
Physical Surface("symmetry_x") = {1};
Physical Surface("side_x") = {2};
Physical Surface("symmetry_y") = {3};
Physical Surface("side_y") = {4};
Physical Surface("bottom") = {5};
Physical Surface("contact") = {6};
