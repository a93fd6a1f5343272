// The upper body (the sphere, by its gap function) of the 3D scale benchmark: a quarter block
// [0, 1]^2 x [0, 1] (solid_scale_block.geo; the same grid on z = 0 as solid_scale_lower.geo).
DefineConstant[ h = 0.1 ];
depth = 1.0;
Include "solid_scale_block.geo";
