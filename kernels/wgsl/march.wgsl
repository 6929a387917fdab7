// The march of kernels/march.cl in WGSL: the same sphere tracing towards
// the surface DETAIL footprints out, the same over-relaxed steps that fall
// back when their unbounding spheres stop overlapping, the same location
// of a hit by regula falsi (the Illinois variant), and the same stop past
// the scene's bounding sphere. Glow, the glow nodes' halos and inside
// shapes' brute-force steps are left out (the WGSL module has none).
//
// The module defines before it: MAX_STEPS, MAX_DISTANCE, DETAIL,
// HIT_EPSILON, OVER_RELAXATION, SCENE_BOUNDED and SCENE_BOUND_CENTRE,
// SCENE_BOUND_RADIUS, SCENE_BOUND_SLOPE (the sphere around the scene, in
// the module's frame; unused where SCENE_BOUNDED is false), and DE.

const MARCH_REFINE_LIMIT: int = 24; // most evaluations spent locating a hit

// Where a march stopped: the distance along the ray, the smallest
// d / (t + d) seen, the distance evaluations, and whether it reached the
// surface.
struct MarchResult {
    t: real,
    closest: real,
    steps: int,
    hit: bool,
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
    var r = MarchResult(start, 1.0, 0, false);
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
            r.closest = min(r.closest, d / (r.t + d));
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
        if (r.t > MAX_DISTANCE || (SCENE_BOUNDED && r.t > t_exit && !relaxed)) {
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
