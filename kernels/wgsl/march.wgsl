// The march of kernels/march.cl in WGSL: the same sphere tracing towards
// the surface DETAIL footprints out, the same over-relaxed steps that fall
// back when their unbounding spheres stop overlapping, the same location
// of a hit by regula falsi (the Illinois variant), the same glow (the
// angle of the nearest miss, and each glow node's) and the same stop past
// the scene's bounding sphere, and the same brute-force steps within the
// region of inside shapes, which have no distance to step by.
//
// The module defines before it: MAX_STEPS, MAX_DISTANCE, DETAIL,
// HIT_EPSILON, OVER_RELAXATION; SCENE_BOUNDED and SCENE_BOUND_CENTRE,
// SCENE_BOUND_RADIUS, SCENE_BOUND_SLOPE (the sphere around the scene, in
// the module's frame; unused where SCENE_BOUNDED is false); the glow:
// ENABLE_GLOW, GLOW_COLOR, GLOW_STRENGTH, GLOW_BOUNDED with
// GLOW_BOUND_CENTRE, GLOW_BOUND_RADIUS, GLOW_BOUND_SLOPE (march.cl's
// ENABLE_GLOW_BOUND), GLOW_NODES (0 without glow nodes), GLOW_SLOTS (at
// least 1) and NODE_GLOW_BRIGHTEST, with glow_distance where GLOW_NODES is
// above 0; inside shapes: ENABLE_BRUTE with BRUTE_CENTRE and BRUTE_RADIUS
// (the sphere they lie in, in the module's frame), BRUTE_STEP,
// BRUTE_MAX_STEPS and INSIDE_HUGE; FSDF_INFINITY; and DE. A constant that is false leaves its code
// unreachable, and the shader compiler drops it.

const MARCH_REFINE_LIMIT: int = 24; // most evaluations spent locating a hit
const MARCH_GLOW_FALLOFF: real = 24.0; // glow ~ exp(-falloff * closest angle)

// Where a march stopped: the distance along the ray, the smallest
// d / (t + d) seen, the distance evaluations, whether it reached the
// surface, and the same angle for each glow node's shape.
struct MarchResult {
    t: real,
    closest: real,
    steps: int,
    hit: bool,
    glow_closest: array<real, GLOW_SLOTS>,
}

// The least d / t along a ray that the glow may skip without changing its
// pixel by more than half a step of an 8-bit channel (march.cl's
// march_glow_slope): 0 without glow, FSDF_INFINITY where no angle is
// small enough.
fn march_glow_slope() -> real {
    if (!ENABLE_GLOW) {
        return 0.0;
    }
    let brightest = max(GLOW_COLOR.x, max(GLOW_COLOR.y, GLOW_COLOR.z)) * GLOW_STRENGTH
                    + NODE_GLOW_BRIGHTEST;
    let angle = log(max(510.0 * brightest, 1.0)) / MARCH_GLOW_FALLOFF;
    if (angle < 1.0) {
        return angle / (1.0 - angle);
    }
    return FSDF_INFINITY;
}

// Whether a ray past the scene's bounding sphere at p, t along it, may
// stop without changing its pixel's glow (march.cl's march_glow_settled).
fn march_glow_settled(p: real3, rd: real3, t: real) -> bool {
    let k = march_glow_slope();
    if (k <= 0.0) {
        return true;
    }
    let q = p - SCENE_BOUND_CENTRE;
    if (dot(q, rd) < 0.0) {
        return false; // still approaching the sphere, which it misses
    }
    let b = k / SCENE_BOUND_SLOPE;
    if (b >= 1.0) {
        return false;
    }
    let a = sqrt(1.0 - b * b);
    return SCENE_BOUND_SLOPE * (a * length(q) - SCENE_BOUND_RADIUS) >= k * t;
}

// A pixel's footprint at distance t along its ray, for a camera whose
// footprint is `footprint.x + footprint.y * t`.
fn march_footprint(footprint: real2, t: real) -> real {
    return footprint.x + footprint.y * t;
}

// Where a ray's brute-force steps start, in [0, 1) of a step: set per
// sample by the brute-force pass (march.cl's MarchCamera.phase).
var<private> march_phase: real = 0.5;

// Where the ray ro + t rd (rd of unit length) is within the sphere the
// inside shapes lie in: (enter, exit), enter > exit where it misses it
// (march.cl's march_brute_span).
fn march_brute_span(ro: real3, rd: real3) -> real2 {
    let oc = ro - BRUTE_CENTRE;
    let b = dot(oc, rd);
    let disc = b * b - (dot(oc, oc) - BRUTE_RADIUS * BRUTE_RADIUS);
    if (disc < 0.0) {
        return real2(1.0, -1.0);
    }
    let root = sqrt(disc);
    return real2(-b - root, -b + root);
}

// A brute-force step within the span: samples at most h apart on a lattice
// that starts phase * h past where the ray enters the sphere, or the
// sphere-tracing step where it is shorter (march.cl's march_brute_step).
// Keeps the next sample in *next (negative before the first).
fn march_brute_step(t: real, step: real, span: real2, h: real, phase: real,
                    next: ptr<function, real>) -> real {
    if (t + step <= span.x || t >= span.y) {
        return step;
    }
    if (*next < 0.0) {
        *next = max(t, span.x) + phase * h;
    }
    if (*next <= t) {
        *next = t + h;
    }
    let to_next = *next - t;
    if (to_next > step) {
        return step;
    }
    *next += h;
    return to_next;
}

fn march_level(ro: real3, rd: real3, footprint: real2, t: real, side: real) -> real {
    return side * (DE(ro + rd * t) - DETAIL * march_footprint(footprint, t));
}

fn march_refine(ro: real3, rd: real3, footprint: real2, t0_in: real, g0_in: real, t1_in: real,
                g1_in: real, side: real, steps: ptr<function, int>) -> real {
    var t0 = t0_in;
    var g0 = g0_in;
    var t1 = t1_in;
    var g1 = g1_in;
    var kept = 0; // which end the last step moved: -1 outside, 1 inside
    for (var i = 0; i < MARCH_REFINE_LIMIT; i++) {
        if (t1 - t0 <= HIT_EPSILON * march_footprint(footprint, t1)) {
            break;
        }
        var t = clamp(t0 + (t1 - t0) * (g0 / (g0 - g1)), t0, t1);
        // An inside shape's value has a sign and no size: halve the bracket.
        if (ENABLE_BRUTE && max(abs(g0), abs(g1)) >= 0.5 * INSIDE_HUGE) {
            t = 0.5 * (t0 + t1);
        }
        let g = march_level(ro, rd, footprint, t, side);
        *steps += 1;
        if (g > 0.0) {
            t0 = t;
            g0 = g;
            if (kept == -1) {
                g1 *= 0.5;
            }
            kept = -1;
        } else {
            t1 = t;
            g1 = g;
            if (g == 0.0) {
                break;
            }
            if (kept == 1) {
                g0 *= 0.5;
            }
            kept = 1;
        }
    }
    return t1;
}

// Where the ray leaves the sphere around the scene, widened by the drawn
// surface's offset at the farthest distance a hit could have (see
// march_bound_exit in march.cl); negative if it misses the sphere.
fn march_bound_exit(ro: real3, rd: real3, footprint: real2) -> real {
    let oc = ro - SCENE_BOUND_CENTRE;
    let len = length(oc);
    let shrink = 1.0 - DETAIL * footprint.y / SCENE_BOUND_SLOPE;
    if (shrink <= 0.0) {
        return MAX_DISTANCE;
    }
    let t_max = (len + SCENE_BOUND_RADIUS + DETAIL * footprint.x / SCENE_BOUND_SLOPE) / shrink;
    let radius = SCENE_BOUND_RADIUS + DETAIL * march_footprint(footprint, t_max) / SCENE_BOUND_SLOPE;
    let b = dot(oc, rd);
    let disc = b * b - (len - radius) * (len + radius);
    if (disc < 0.0) {
        return -1.0;
    }
    return -b + sqrt(disc);
}

// Side 1 marches towards the surface from outside, side -1 towards the
// way out from inside it.
fn march_ray(ro: real3, rd: real3, start: real, footprint: real2, side: real) -> MarchResult {
    var r: MarchResult;
    r.t = start;
    r.closest = 1.0;
    r.steps = 0;
    r.hit = false;
    for (var k = 0; k < GLOW_NODES; k++) {
        r.glow_closest[k] = 1.0;
    }
    // The angle beyond which no glow node's halo shows (march_glow_slope).
    let glow_reach = log(max(510.0 * NODE_GLOW_BRIGHTEST, 1.0)) / MARCH_GLOW_FALLOFF;
    let lipschitz = 1.0 + DETAIL * footprint.y;
    var omega = OVER_RELAXATION;
    var relaxed = false; // whether the last step was longer than a plain one
    var prev_t = start;
    var prev_g = 0.0;
    var hit_g = 0.0;
    // A ray that has passed the last place it could hit stops (after a
    // plain step: a relaxed one may still fall back before it).
    var t_exit = MAX_DISTANCE;
    if (SCENE_BOUNDED) {
        t_exit = march_bound_exit(ro, rd, footprint);
    }
    var span = real2(1.0, -1.0);
    if (ENABLE_BRUTE) {
        span = march_brute_span(ro, rd);
    }
    var next_sample = -1.0;
    var brute_steps = 0;
    for (var i = 0; i < MAX_STEPS; i++) {
        let d = DE(ro + rd * r.t);
        let g = side * (d - DETAIL * march_footprint(footprint, r.t));
        r.steps += 1;
        if (relaxed && (g < 0.0 || prev_g + g < lipschitz * (r.t - prev_t))) {
            r.t = prev_t + prev_g / lipschitz;
            omega = 1.0;
            relaxed = false;
            continue;
        }
        if (d > 0.0) {
            var near = d;
            if (GLOW_BOUNDED) {
                // Only the shapes that glow count: a near miss of an
                // unbounded shape far from them (a floor, at the horizon)
                // does not glow.
                near = max(d, GLOW_BOUND_SLOPE * (length(ro + rd * r.t - GLOW_BOUND_CENTRE)
                                                  - GLOW_BOUND_RADIUS));
            }
            r.closest = min(r.closest, near / (r.t + near));
            // Each glow node's own shape, where the scene's surface is
            // close enough for a halo to show.
            if (GLOW_NODES > 0 && d / (r.t + d) < glow_reach) {
                for (var k = 0; k < GLOW_NODES; k++) {
                    let dk = max(glow_distance(k, ro + rd * r.t), 0.0);
                    r.glow_closest[k] = min(r.glow_closest[k], dk / (r.t + dk));
                }
                r.steps += GLOW_NODES;
            }
        }
        if (g <= 0.0) {
            r.hit = true;
            r.closest = 0.0;
            hit_g = g;
            break;
        }
        let plain = g / lipschitz;
        let shortest = HIT_EPSILON * march_footprint(footprint, r.t);
        relaxed = omega > 1.0 && omega * plain > max(plain, shortest);
        var step = max(omega * plain, shortest);
        if (ENABLE_BRUTE) {
            let h = BRUTE_STEP * march_footprint(footprint, max(r.t, span.x));
            let brute = march_brute_step(r.t, step, span, h, march_phase, &next_sample);
            if (brute < step) {
                // A brute-force step: never relaxed, and not one of the
                // MAX_STEPS the sphere tracing may take (BRUTE_MAX_STEPS
                // more).
                step = brute;
                relaxed = false;
                if (brute_steps < BRUTE_MAX_STEPS) {
                    brute_steps += 1;
                    i -= 1;
                }
            }
        }
        prev_t = r.t;
        prev_g = g;
        r.t += step;
        if (r.t > MAX_DISTANCE) {
            break;
        }
        if (SCENE_BOUNDED && r.t > t_exit && !relaxed
            && march_glow_settled(ro + rd * r.t, rd, r.t)) {
            break;
        }
    }
    // The hit is located after the loop, not in it: where invocations run
    // side by side as the lanes of a vector, they then locate their hits
    // together rather than each in turn.
    if (r.hit && r.steps > 1) {
        var steps = r.steps;
        r.t = march_refine(ro, rd, footprint, prev_t, prev_g, r.t, hit_g, side, &steps);
        r.steps = steps;
    }
    return r;
}
