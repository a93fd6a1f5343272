// The lower body of examples/hertz_3d.toml: a quarter block [0, 1]^2 x [-1, 0], its contact
// face z = 0 graded towards the origin (hertz_3d_block.geo; `h` the finest cell size).
DefineConstant[ h = 0.01 ];
depth = -1.0;
Include "hertz_3d_block.geo";
