// The upper body of examples/hertz_3d.toml: a quarter block [0, 1]^2 x [0, 1], its contact
// face z = 0 graded towards the origin as the lower body's (the same grid: matching meshes).
DefineConstant[ h = 0.01 ];
depth = 1.0;
Include "hertz_3d_block.geo";
