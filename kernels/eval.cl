/* Point evaluator: DE and DE_shade at each point, for checking the OpenCL
   formulas against the CPU reference. The header defines the argument list
   (EVAL_POINTS_ARGS). Per point, EVAL_OUT_STRIDE reals:
   out[2i] = (DE, DE_shade, trap, 0), out[2i + 1] = (colour, 0). */
__kernel void eval_points(EVAL_POINTS_ARGS) {
    uint i = get_global_id(0);
    if (i >= count) {
        return;
    }
    real3 p = points[i].xyz;
    real3 color;
    real trap;
    real d = DE(p, params);
    real shaded = DE_shade(p, params, &color, &trap);
    out[2 * i] = (real4)(d, shaded, trap, R(0.0));
    out[2 * i + 1] = (real4)(color, R(0.0));
}
