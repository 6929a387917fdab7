// march.cl — the reusable sphere tracer: camera rays, the march, the stop
// at the scene's bound and the brute-force steps of inside shapes.
//
// The render program is march.cl, shade.cl, optics.cl, paths.cl and
// render.cl, in that order, appended after the generated header and the
// scene's distance functions. They use only:
//   types   real, real2, real3, real4 and the literal macro R(x)
//   consts  REAL_TINY MAX_STEPS MAX_DISTANCE DETAIL HIT_EPSILON
//           NORMAL_EPSILON OVER_RELAXATION SUPERSAMPLING GAMMA SKY_TOP
//           SKY_BOTTOM EXPOSURE_SCALE
//   display real3 display_color(real3 c, real scale, real inverse_gamma),
//           the display transform (exposure, tone curve, gamma) printed
//           from quality::display_formula
//   scene   real DE(real3 p, __global const real* params)
//           real DE_shade(real3 p, __global const real* params,
//                         real3* color, real2* trap), trap.x the orbit
//                         trap that tints the colour and trap.y the trap
//                         the layers show (a palette's too)
//           and, with materials (ENABLE_MATERIALS), void DE_material(real3 p,
//           __global const real* params, real16* material), whose fields the
//           header names MATERIAL_<value> (material.MATERIAL_IOR)
//   effects: the code of each effect (ambient occlusion, shadows, glow,
//           fog, global illumination: ENABLE_GI with GI_BOUNCES) sits in
//           a conditional block named ENABLE_<effect>, with its
//           constants defined by the header only when it is on, and so
//           does the stop at the scene's bounding sphere
//           (ENABLE_SCENE_BOUND: SCENE_BOUND_CENTRE, SCENE_BOUND_RADIUS,
//           SCENE_BOUND_SLOPE), the coarse pass (ENABLE_CONE:
//           CONE_TILE, the cone_starts kernel and the starts it leaves),
//           direct lighting (ENABLE_DIRECT: on unless global illumination
//           is) and the sky along a ray (ENABLE_SKY_RAYS: march_sky, for
//           materials' rays and paths).
//           Code generation resolves these blocks
//           itself and leaves out every one that is off, so they are the
//           only preprocessor conditionals allowed in these files.
//
// Everything else arrives at run time, so moving the camera or the lights
// and changing dynamic parameters never rebuilds the program. The header
// defines the kernel's argument list (RENDER_TILE_ARGS) and the layouts of
// the camera buffer (CAMERA_<field>: the offset of each field), of the
// light buffer (LIGHT_<field>, LIGHT_STRIDE reals per light) and of the
// shading layers (LAYER_<field>, LAYER_STRIDE floats per pixel, written
// when write_aovs is WRITE_LAYERS), from the tables the host packs and
// reads them with (src/codegen/interface.rs).
//
// Positions (the camera's origin, point lights) are relative to the
// program's origin, the scene's outermost translation, which the host
// subtracts in f64; DE takes points in the same frame. A pixel is
// footprint_base + footprint_per_unit * t scene units wide at distance t
// along a ray: perspective cameras have a per-unit term and a tiny base that
// keeps thresholds above zero at t = 0; orthographic cameras have only the
// base.

// Shading constants that are not quality knobs.
#define MARCH_AMBIENT R(0.5)      // strength of the sky's hemisphere light
#define MARCH_SPECULAR R(0.25)    // Blinn-Phong specular strength
#define MARCH_SHININESS R(32.0)   // Blinn-Phong exponent
#define MARCH_NORMAL_EVALUATIONS 4u // DE calls of march_normal
#define MARCH_REFINE_LIMIT 24     // most evaluations spent locating a hit
#ifdef ENABLE_GLOW
#define MARCH_GLOW_FALLOFF R(24.0) // glow ~ exp(-falloff * closest angle)
#endif

typedef struct {
    real t;         // distance along the ray where the march stopped
    real closest;   // smallest d / (t + d) seen: the angle of the nearest miss
    int steps;      // distance evaluations
    int hit;        // 1 if the surface was reached
#ifdef ENABLE_NODE_GLOW
    real glow_closest[GLOW_NODES]; // the same angle for each glow node's shape
#endif
} MarchResult;

typedef struct {
    real3 origin;
    real3 right;
    real3 up;
    real3 forward;
    real half_w;
    real half_h;
    real footprint_base;
    real footprint_per_unit;
    real image_w;     // the image's size in pixels
    real image_h;
    real pixel_scale; // image pixels per rendered pixel along each axis
    real2 shift;      // the image window's offset, in units of half_h
    real aperture;    // the thin lens's radius (0: a pinhole)
    real focus;       // the distance along forward that is in focus
    int orthographic;
    real phase;       // where a ray's brute-force steps start, in [0, 1) of a step
} MarchCamera;

MarchCamera march_load_camera(__global const real* c) {
    MarchCamera cam;
    cam.origin = vload3(0, c + CAMERA_ORIGIN);
    cam.orthographic = c[CAMERA_ORTHOGRAPHIC] > R(0.5);
    cam.right = vload3(0, c + CAMERA_RIGHT);
    cam.half_w = c[CAMERA_HALF_WIDTH];
    cam.up = vload3(0, c + CAMERA_UP);
    cam.half_h = c[CAMERA_HALF_HEIGHT];
    cam.forward = vload3(0, c + CAMERA_FORWARD);
    cam.footprint_base = c[CAMERA_FOOTPRINT_BASE];
    cam.footprint_per_unit = c[CAMERA_FOOTPRINT_PER_UNIT];
    cam.image_w = c[CAMERA_IMAGE_WIDTH];
    cam.image_h = c[CAMERA_IMAGE_HEIGHT];
    cam.pixel_scale = c[CAMERA_PIXEL_SCALE];
    cam.shift = vload2(0, c + CAMERA_SHIFT);
    cam.aperture = c[CAMERA_APERTURE];
    cam.focus = c[CAMERA_FOCUS_DISTANCE];
    cam.phase = R(0.5);
    return cam;
}

// Scene units covered by one pixel at distance t along a ray.
real march_footprint(const MarchCamera* cam, real t) {
    return cam->footprint_base + cam->footprint_per_unit * t;
}

// The ray through image position (px, py) in image pixels, (0, 0) being
// the top left corner of the image, through the centre of the lens.
void march_camera_ray(const MarchCamera* cam, real px, real py, real3* ro, real3* rd) {
    real u = (R(2.0) * px / cam->image_w - R(1.0)) * cam->half_w + cam->shift.x * cam->half_h;
    real v = (R(1.0) - R(2.0) * py / cam->image_h + cam->shift.y) * cam->half_h;
    if (cam->orthographic) {
        *ro = cam->origin + cam->right * u + cam->up * v;
        *rd = cam->forward;
    } else {
        *ro = cam->origin;
        *rd = normalize(cam->forward + cam->right * u + cam->up * v);
    }
}

// The ray through image position (px, py) and the point (lx, ly) of the
// unit disc scaled to the lens: it leaves the lens there and meets the
// ray through the lens's centre on the plane in focus, FOCUS_DISTANCE
// along forward. A pinhole camera (aperture 0) keeps the centre's ray.
void march_lens_ray(const MarchCamera* cam, real px, real py, real2 lens, real3* ro,
                    real3* rd) {
    march_camera_ray(cam, px, py, ro, rd);
    if (cam->aperture > R(0.0)) {
        real3 focus = *ro + *rd * (cam->focus / dot(*rd, cam->forward));
        *ro += (cam->right * lens.x + cam->up * lens.y) * cam->aperture;
        *rd = normalize(focus - *ro);
    }
}

// The drawn surface: where the distance estimate falls to DETAIL pixel
// footprints. g(t) is how far the point at t along the ray lies outside it
// (side 1), or inside it (side -1: a ray travelling inside a transparent
// shape, looking for the way out).
real march_level(real3 ro, real3 rd, const MarchCamera* cam, real t, real side,
                 __global const real* params) {
    return side * (DE(ro + rd * t, params) - DETAIL * march_footprint(cam, t));
}

// Locates the crossing of the surface between t0 (outside, g0 > 0) and t1
// (inside, g1 <= 0) to HIT_EPSILON pixel footprints along the ray, by the
// Illinois form of regula falsi: exact in one evaluation where the
// distance is linear along the ray (a plane, a sphere met head-on), and
// superlinear elsewhere. Returns the inside end of the final bracket and
// adds its evaluations to *steps.
real march_refine(real3 ro, real3 rd, const MarchCamera* cam, real t0, real g0, real t1,
                  real g1, real side, __global const real* params, int* steps) {
    int kept = 0; // which end the last step moved: -1 outside, 1 inside
    for (int i = 0; i < MARCH_REFINE_LIMIT; ++i) {
        if (t1 - t0 <= HIT_EPSILON * march_footprint(cam, t1)) {
            break;
        }
        real t = clamp(t0 + (t1 - t0) * (g0 / (g0 - g1)), t0, t1);
#ifdef ENABLE_BRUTE
        // An inside shape's value has a sign and no size: halve the bracket.
        if (fmax(fabs(g0), fabs(g1)) >= R(0.5) * INSIDE_HUGE) {
            t = R(0.5) * (t0 + t1);
        }
#endif
        real g = march_level(ro, rd, cam, t, side, params);
        *steps += 1;
        if (g > R(0.0)) {
            t0 = t;
            g0 = g;
            if (kept == -1) {
                g1 *= R(0.5);
            }
            kept = -1;
        } else {
            t1 = t;
            g1 = g;
            if (g == R(0.0)) {
                break;
            }
            if (kept == 1) {
                g0 *= R(0.5);
            }
            kept = 1;
        }
    }
    return t1;
}

// Sphere tracing towards the surface DETAIL pixel footprints out: each
// step is the distance g to that surface (divided by g's Lipschitz bound,
// which the footprint term raises a little above 1), so for an estimator
// that never overestimates a step of that distance never passes the first
// crossing. Steps are at least HIT_EPSILON footprints long, so a ray that
// approaches the surface at a grazing angle crosses it in a bounded number
// of steps, and features thinner than that along the ray may be missed.
// Once a step lands inside, march_refine locates the crossing. The surface
// itself does not depend on how the march gets there: MAX_STEPS,
// OVER_RELAXATION and HIT_EPSILON change the cost and how closely the
// march finds it (thin features missed, rays that run out of steps), not
// where it lies.
// OVER_RELAXATION below 1 shortens every step, a guard against estimators
// that overestimate. Above 1 the steps are lengthened (Keinert et al.
// 2014); when the unbounding spheres of two consecutive points stop
// overlapping the long step may have jumped over a surface, so the march
// returns to the last safe point and continues with plain steps.
// The glow of a pixel is set by the smallest d / (t + d) along its ray.
// Space the march may skip without changing the glow by more than half a
// step of an 8-bit pixel must keep every d / (t + d) above the angle L
// where the glow falls below that (its strength times exp(-falloff * L)
// times its brightest channel = 0.5 / 255), that is d >= k t with
// k = L / (1 - L). Returns k: 0 without glow, and INFINITY where no angle
// is small enough.
real march_glow_slope(void) {
#ifdef ENABLE_GLOW
    real brightest = fmax(GLOW_COLOR.x, fmax(GLOW_COLOR.y, GLOW_COLOR.z)) * GLOW_STRENGTH;
#ifdef ENABLE_NODE_GLOW
    // The glow nodes' halos, as bright as they add up to as the program
    // was built.
    brightest += NODE_GLOW_BRIGHTEST;
#endif
    real angle = log(fmax(R(510.0) * brightest, R(1.0))) / MARCH_GLOW_FALLOFF;
    return angle < R(1.0) ? angle / (R(1.0) - angle) : (real)INFINITY;
#endif
    return R(0.0);
}

#ifdef ENABLE_SCENE_BOUND
// How far along the ray a hit can lie at most, for a scene that lies in a
// sphere (SCENE_BOUND_CENTRE, SCENE_BOUND_RADIUS) outside which its
// estimate is at least SCENE_BOUND_SLOPE times the distance to the sphere
// (src/ir/bounds.rs). The drawn surface lies DETAIL footprints out, so
// the sphere is widened by that at the farthest distance a hit could have,
// t_max = (|ro - c| + R + DETAIL base / slope) / (1 - DETAIL per_unit /
// slope): beyond t_max the estimate outgrows the surface's offset, and
// before it, once the ray has left the widened sphere it never returns.
// Returns where the ray leaves the widened sphere (negative if it misses
// it), or MAX_DISTANCE where the footprint grows too fast for the bound.
real march_bound_exit(real3 ro, real3 rd, const MarchCamera* cam) {
    real3 oc = ro - SCENE_BOUND_CENTRE;
    real len = length(oc);
    real shrink = R(1.0) - DETAIL * cam->footprint_per_unit / SCENE_BOUND_SLOPE;
    if (shrink <= R(0.0)) {
        return MAX_DISTANCE;
    }
    real t_max = (len + SCENE_BOUND_RADIUS + DETAIL * cam->footprint_base / SCENE_BOUND_SLOPE)
                 / shrink;
    real radius = SCENE_BOUND_RADIUS + DETAIL * march_footprint(cam, t_max) / SCENE_BOUND_SLOPE;
    real b = dot(oc, rd);
    real disc = b * b - (len - radius) * (len + radius);
    return disc < R(0.0) ? R(-1.0) : -b + sqrt(disc);
}

// Whether a ray past the scene's bounding sphere at p, t along it in
// direction rd, may stop without changing its pixel: always, unless the
// pixel has a halo of near misses (see march_glow_slope). Further on, u
// along the ray, the estimate is at least G = slope (sqrt(|q|^2 + u^2) - R)
// with q = p - c (once the ray moves away from c). For any unit (a, b),
// sqrt(|q|^2 + u^2) >= a |q| + b u; with b = k / slope the u terms match
// k (t + u), so slope (a |q| - R) >= k t suffices for every u.
int march_glow_settled(real3 p, real3 rd, real t) {
    real k = march_glow_slope();
    if (k <= R(0.0)) {
        return 1;
    }
    real3 q = p - SCENE_BOUND_CENTRE;
    if (dot(q, rd) < R(0.0)) {
        return 0; // still approaching the sphere, which it misses
    }
    real b = k / SCENE_BOUND_SLOPE;
    if (b >= R(1.0)) {
        return 0;
    }
    real a = sqrt(R(1.0) - b * b);
    return SCENE_BOUND_SLOPE * (a * length(q) - SCENE_BOUND_RADIUS) >= k * t;
}
#endif

#ifdef ENABLE_BRUTE
// Where the ray ro + t rd (rd of unit length) is within the sphere the
// inside shapes lie in (BRUTE_CENTRE, BRUTE_RADIUS): (enter, exit), with
// enter > exit where it misses the sphere.
real2 march_brute_span(real3 ro, real3 rd) {
    real3 oc = ro - BRUTE_CENTRE;
    real b = dot(oc, rd);
    real disc = b * b - (dot(oc, oc) - BRUTE_RADIUS * BRUTE_RADIUS);
    if (disc < R(0.0)) {
        return (real2)(R(1.0), R(-1.0));
    }
    real root = sqrt(disc);
    return (real2)(-b - root, -b + root);
}

// Brute-force marching. Inside shapes have no distance (their value is
// +-INSIDE_HUGE), so within their sphere a ray samples points at most h
// apart and asks only for the sign. The samples form a lattice that
// starts phase * h past where the ray enters the sphere (or past t, where
// it starts within it) and continues h apart; a sphere-tracing step
// shorter than the way to the next sample (near a distance-estimated
// surface) is taken as it is, and the lattice resumes from the sample it
// did not reach. Returns the step from t, at most `step`, and keeps the
// next sample in *next (negative before the first).
real march_brute_step(real t, real step, real2 span, real h, real phase, real* next) {
    if (t + step <= span.x || t >= span.y) {
        return step;
    }
    if (*next < R(0.0)) {
        *next = fmax(t, span.x) + phase * h;
    }
    if (*next <= t) {
        *next = t + h;
    }
    real to_next = *next - t;
    if (to_next > step) {
        return step;
    }
    *next += h;
    return to_next;
}
#endif

// Side 1 marches towards the surface from outside, side -1 towards the
// way out from inside it (g and its Lipschitz bound are the same up to
// sign).
MarchResult march_ray(real3 ro, real3 rd, real start, const MarchCamera* cam, real side,
                      __global const real* params) {
    MarchResult r;
    r.t = start;
    r.closest = R(1.0);
    r.steps = 0;
    r.hit = 0;
#ifdef ENABLE_NODE_GLOW
    for (int k = 0; k < GLOW_NODES; ++k) {
        r.glow_closest[k] = R(1.0);
    }
    // The angle beyond which no glow node's halo shows (march_glow_slope).
    const real glow_reach = log(fmax(R(510.0) * NODE_GLOW_BRIGHTEST, R(1.0))) / MARCH_GLOW_FALLOFF;
#endif
    const real lipschitz = R(1.0) + DETAIL * cam->footprint_per_unit;
    real omega = OVER_RELAXATION;
    int relaxed = 0; // whether the last step was longer than a plain one
    real prev_t = start;
    real prev_g = R(0.0);
#ifdef ENABLE_SCENE_BOUND
    // A ray that has passed the last place it could hit stops (after a
    // plain step: a relaxed one may still fall back before it).
    const real t_exit = march_bound_exit(ro, rd, cam);
#endif
#ifdef ENABLE_BRUTE
    const real2 span = march_brute_span(ro, rd);
    real next_sample = R(-1.0);
    int brute_steps = 0;
#endif
    for (int i = 0; i < MAX_STEPS; ++i) {
        real d = DE(ro + rd * r.t, params);
        real g = side * (d - DETAIL * march_footprint(cam, r.t));
        r.steps += 1;
        if (relaxed && (g < R(0.0) || prev_g + g < lipschitz * (r.t - prev_t))) {
            r.t = prev_t + prev_g / lipschitz;
            omega = R(1.0);
            relaxed = 0;
            continue;
        }
        if (d > R(0.0)) {
            real near = d;
#ifdef ENABLE_GLOW_BOUND
            // Only the shapes that glow count: their distance is at least
            // that of their sphere, so a near miss of an unbounded shape
            // (a floor, at the horizon) far from them does not glow.
            near = fmax(d, GLOW_BOUND_SLOPE * (length(ro + rd * r.t - GLOW_BOUND_CENTRE)
                                               - GLOW_BOUND_RADIUS));
#endif
            r.closest = fmin(r.closest, near / (r.t + near));
#ifdef ENABLE_NODE_GLOW
            // Each glow node's own shape, where the scene's surface is
            // close enough for a halo to show (a shape in a union is no
            // nearer than it).
            if (d / (r.t + d) < glow_reach) {
                for (int k = 0; k < GLOW_NODES; ++k) {
                    real dk = fmax(glow_distance(k, ro + rd * r.t, params), R(0.0));
                    r.glow_closest[k] = fmin(r.glow_closest[k], dk / (r.t + dk));
                }
                r.steps += GLOW_NODES;
            }
#endif
        }
        if (g <= R(0.0)) {
            r.hit = 1;
            r.closest = R(0.0);
            if (r.steps > 1) {
                r.t = march_refine(ro, rd, cam, prev_t, prev_g, r.t, g, side, params, &r.steps);
            }
            return r;
        }
        real plain = g / lipschitz;
        real shortest = HIT_EPSILON * march_footprint(cam, r.t);
        relaxed = omega > R(1.0) && omega * plain > fmax(plain, shortest);
        real step = fmax(omega * plain, shortest);
#ifdef ENABLE_BRUTE
        real h = BRUTE_STEP * march_footprint(cam, fmax(r.t, span.x));
        real brute = march_brute_step(r.t, step, span, h, cam->phase, &next_sample);
        if (brute < step) {
            // A brute-force step: never relaxed, and not one of the
            // MAX_STEPS the sphere tracing may take (BRUTE_MAX_STEPS more).
            step = brute;
            relaxed = 0;
            if (brute_steps < BRUTE_MAX_STEPS) {
                brute_steps += 1;
                i -= 1;
            }
        }
#endif
        prev_t = r.t;
        prev_g = g;
        r.t += step;
        if (r.t > MAX_DISTANCE) {
            return r;
        }
#ifdef ENABLE_SCENE_BOUND
        if (r.t > t_exit && !relaxed && march_glow_settled(ro + rd * r.t, rd, r.t)) {
            return r;
        }
#endif
    }
    return r;
}
