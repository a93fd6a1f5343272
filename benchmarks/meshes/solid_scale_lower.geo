// The flat (lower) body of the 3D scale benchmark: a quarter block [0, 1]^2 x [-1, 0]
// (solid_scale_block.geo; n = Round(1 / h) cells per direction).
DefineConstant[ h = 0.1 ];
depth = -1.0;
Include "solid_scale_block.geo";
