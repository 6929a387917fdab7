/* Point evaluator: DE and DE_shade at each point, for checking the OpenCL
   formulas against the CPU reference and for shading mesh vertices. The
   header defines the argument lists (EVAL_POINTS_ARGS,
   EVAL_DISTANCES_ARGS, EVAL_GRID_ARGS). Per point, EVAL_OUT_STRIDE reals:
   out[2i] = (DE, DE_shade, tint trap, layer trap), out[2i + 1] =
   (colour, 0). */
__kernel void eval_points(EVAL_POINTS_ARGS) {
    uint i = get_global_id(0);
    if (i >= count) {
        return;
    }
    real3 p = points[i].xyz;
    real3 color;
    real2 trap;
    real d = DE(p, params);
    real shaded = DE_shade(p, params, &color, &trap);
    out[2 * i] = (real4)(d, shaded, trap.x, trap.y);
    out[2 * i + 1] = (real4)(color, R(0.0));
}

/* Distances only: DE at each point, one real per point (fitting mesh
   vertices, culling). */
__kernel void eval_distances(EVAL_DISTANCES_ARGS) {
    uint i = get_global_id(0);
    if (i >= count) {
        return;
    }
    out[i] = DE(points[i].xyz, params);
}

/* Grid evaluator: DE at every sample of cubic blocks of a regular grid, for
   meshes and volumes. Sample s = x + side (y + side z) of block b lies at
   grid.xyz + grid.w (blocks[b].xyz + (x, y, z)) and goes to
   out[b side^3 + s]: only distances travel, no points. */
__kernel void eval_grid(EVAL_GRID_ARGS) {
    uint i = get_global_id(0);
    if (i >= count) {
        return;
    }
    uint per = side * side * side;
    uint b = i / per;
    uint s = i - b * per;
    int4 at = blocks[b];
    real3 index = (real3)((real)(at.x + (int)(s % side)),
                          (real)(at.y + (int)((s / side) % side)),
                          (real)(at.z + (int)(s / (side * side))));
    real3 p = (real3)(grid[0], grid[1], grid[2]) + grid[3] * index;
    out[i] = DE(p, params);
}
