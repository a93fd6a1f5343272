// The upper body of examples/hertz_3d.toml (the sphere): a quarter block
// [0, 1]^2 x [0, 1] whose contact face z = 0 has cells of size h near the axis
// (hertz_3d_block.geo; the same grid for both bodies: matching meshes).
DefineConstant[ h = 0.01 ];
depth = 1.0;
Include "hertz_3d_block.geo";
