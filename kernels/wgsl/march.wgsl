// The march of kernels/march.cl in WGSL: the same sphere tracing towards
// the surface DETAIL footprints out, the same over-relaxed steps that fall
// back when their unbounding spheres stop overlapping, the same location
// of a hit by regula falsi (the Illinois variant), the same glow (the
// angle of the nearest miss, and each glow node's) and the same stop past
// the scene's bounding sphere. Inside shapes' brute-force steps are left
// out (the WGSL backend refuses inside shapes).
//
// The module defines before it: MAX_STEPS, MAX_DISTANCE, DETAIL,
// HIT_EPSILON, OVER_RELAXATION; SCENE_BOUNDED and SCENE_BOUND_CENTRE,
// SCENE_BOUND_RADIUS, SCENE_BOUND_SLOPE (the sphere around the scene, in
// the module's frame; unused where SCENE_BOUNDED is false); the glow:
// ENABLE_GLOW, GLOW_COLOR, GLOW_STRENGTH, GLOW_BOUNDED with
// GLOW_BOUND_CENTRE, GLOW_BOUND_RADIUS, GLOW_BOUND_SLOPE (march.cl's
// ENABLE_GLOW_BOUND), GLOW_NODES (0 without glow nodes), GLOW_SLOTS (at
// least 1) and NODE_GLOW_BRIGHTEST, with glow_distance where GLOW_NODES is
// above 0; FSDF_INFINITY; and DE. A constant that is false leaves its code
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
        let t = clamp(t0 + (t1 - t0) * (g0 / (g0 - g1)), t0, t1);
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
        let step = max(omega * plain, shortest);
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
