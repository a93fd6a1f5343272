// A solid block [0, 1] x [0, 0.6] x [0, 0.4] meshed with tetrahedra (unstructured); its six
// sides are physical surfaces named as make_box_mesh names them. `h` is the element size.
DefineConstant[ h = 0.2 ];
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 0.6, 0.4};
MeshSize{ PointsOf{ Volume{1}; } } = h;
Physical Volume("block") = {1};
// OpenCASCADE's box faces: 1 x = 0, 2 x = 1, 3 y = 0, 4 y = 0.6, 5 z = 0, 6 z = 0.4.
Physical Surface("left") = {1};
Physical Surface("right") = {2};
Physical Surface("front") = {3};
Physical Surface("back") = {4};
Physical Surface("bottom") = {5};
Physical Surface("top") = {6};
