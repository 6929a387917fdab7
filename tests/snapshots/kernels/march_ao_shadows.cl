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

typedef struct {
    real t;         // distance along the ray where the march stopped
    real closest;   // smallest d / (t + d) seen: the angle of the nearest miss
    int steps;      // distance evaluations
    int hit;        // 1 if the surface was reached
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
    return R(0.0);
}

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
    const real lipschitz = R(1.0) + DETAIL * cam->footprint_per_unit;
    real omega = OVER_RELAXATION;
    int relaxed = 0; // whether the last step was longer than a plain one
    real prev_t = start;
    real prev_g = R(0.0);
    // A ray that has passed the last place it could hit stops (after a
    // plain step: a relaxed one may still fall back before it).
    const real t_exit = march_bound_exit(ro, rd, cam);
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
            r.closest = fmin(r.closest, near / (r.t + near));
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
        prev_t = r.t;
        prev_g = g;
        r.t += step;
        if (r.t > MAX_DISTANCE) {
            return r;
        }
        if (r.t > t_exit && !relaxed && march_glow_settled(ro + rd * r.t, rd, r.t)) {
            return r;
        }
    }
    return r;
}
// shade.cl — normals, occlusion, shadows and the shading of a hit.
//
// Follows march.cl in every render program (see its header for what the
// files may use): the tetrahedral normal, ambient occlusion (ENABLE_AO),
// soft shadows (ENABLE_SHADOWS), the orbit-trap tint, the background, the
// materials' shading models (ENABLE_MATERIALS) and march_shade, which
// lights a hit with every light.

// Unit normal by tetrahedral differences (MARCH_NORMAL_EVALUATIONS
// evaluations) with step h.
real3 march_normal(real3 p, real h, real3 rd, __global const real* params) {
    const real2 k = (real2)(R(1.0), R(-1.0));
    real3 g = k.xyy * DE(p + k.xyy * h, params) + k.yyx * DE(p + k.yyx * h, params)
            + k.yxy * DE(p + k.yxy * h, params) + k.xxx * DE(p + k.xxx * h, params);
    real len = length(g);
    // A flat gradient (inside a thin feature, or at a cusp): face the viewer.
    return len > REAL_TINY ? g / len : -rd;
}

// The normal n of a surface that a ray along rd reached from outside,
// which faces the ray. Differences over a step wider than the detail
// beneath it (a fractal's dust) can point away; mirrored towards the
// viewer, occlusion and shadow rays leave the surface instead of starting
// inside it and darkening a lit pixel to black.
real3 march_facing(real3 n, real3 rd) {
    real away = dot(n, rd);
    return away > R(0.0) ? normalize(n - R(2.0) * away * rd) : n;
}

// Ambient occlusion: how much closer the surface is than expected along
// the normal out to a reach r, nearer points weighing more:
//   1 - integral of w(h) clamp(h - DE(p + n h), 0, h) dh
//     / integral of w(h) h dh,   w(h) = exp(-AO_FALLOFF h / r),
// by the midpoint rule with AO_SAMPLES points. The integral is fixed, so
// more samples converge on the same value rather than reaching further.
// 1 on an open face, towards 0 in a crease. Evaluates DE AO_SAMPLES times.
//
// The reach r is AO_DISTANCE, or AO_VIEW_FRACTION of view_height (the
// height the image covers at p's distance: 2 tan(fov / 2) t in
// perspective, the visible height in orthographic) where that is shorter.
// The second is an angle, the same at every resolution, so a view
// magnified any number of times is occluded like the view unmagnified
// rather than by structure far outside it. With the default AO_DISTANCE
// (0.25), a scene of unit size seen from a few units (view_height above
// 1.25) keeps AO_DISTANCE.
#define AO_FALLOFF R(1.5)
// Occlusion never goes below this: where every sample lands inside the
// shape (dust finer than the normal's step, a crevice narrower than the
// first sample) the estimate knows no more than "dark", and a surface
// under the sky keeps a trace of its light instead of reading as a hole.
#define AO_FLOOR R(0.015625) // 2^-6
#define AO_VIEW_FRACTION R(0.2)
real march_ambient_occlusion(real3 p, real3 n, real view_height, real offset,
                             __global const real* params) {
    real reach = fmax(fmin(AO_DISTANCE, AO_VIEW_FRACTION * view_height), REAL_TINY);
    real missing = R(0.0);
    real expected = R(0.0);
    for (int i = 0; i < AO_SAMPLES; ++i) {
        real h = reach * ((real)i + offset) / (real)AO_SAMPLES;
        real weight = exp(-AO_FALLOFF * h / reach);
        real d = DE(p + n * h, params);
        missing += weight * clamp(h - d, R(0.0), h);
        expected += weight * h;
    }
    return clamp(R(1.0) - missing / expected, AO_FLOOR, R(1.0));
}

// Visibility of a light from ro along rd, from distance start to max_t: 0
// in full shadow, 1 fully lit. softness 0 gives a hard shadow; above 0,
// Quilez's improved soft shadow (2018) with a penumbra that grows with
// softness. The ray is blocked where it comes within eps of a surface;
// callers pass a fraction of the surface hit threshold so shadows are not
// fattened by a pixel where objects nearly touch. Adds its DE evaluations
// to *evals.
//
// The ray stops early where the rest cannot change the pixel: once the
// light it could still let through is below half a step of an 8-bit pixel
// (`weight` is the most light a fully visible light adds to the pixel in
// any channel, and the smoothstep below is at most 3 v^2), and, for a
// hard shadow, once it has passed the scene's bounding sphere (nothing
// beyond can block it).
real march_shadow(real3 ro, real3 rd, real max_t, real eps, real start, real softness,
                  real weight, __global const real* params, uint* evals) {
    real visible = R(1.0);
    real prev_h = R(1e20);
    real prev_step = R(0.0); // from the previous sample to this one
    real t = start;
    real faint = sqrt(R(0.5) / (R(255.0) * R(3.0) * fmax(weight, REAL_TINY)));
    real3 oc = ro - SCENE_BOUND_CENTRE;
    real b = dot(oc, rd);
    real widened = SCENE_BOUND_RADIUS + eps / SCENE_BOUND_SLOPE;
    real disc = b * b - (dot(oc, oc) - widened * widened);
    // Where the ray leaves the sphere widened until the estimate outside it
    // exceeds eps (negative: it misses it).
    real t_exit = disc < R(0.0) ? R(-1.0) : -b + sqrt(disc);
    if (softness <= R(0.0)) {
        max_t = fmin(max_t, t_exit);
    }
    for (int i = 0; i < SHADOW_STEPS && t < max_t; ++i) {
        real h = DE(ro + rd * t, params);
        *evals += 1u;
        if (h < eps) {
            return R(0.0);
        }

        if (softness > R(0.0)) {
            // The closest point to the surface between this sample and the
            // previous one, estimated from the two distance spheres: where
            // they cross, y back along the ray. They cross only if h < 2
            // prev_h, always true of an exact distance but not of every
            // estimator (or after a minimum-length step), and the crossing
            // is between the two samples only if y < prev_step; a distance
            // that nearly doubles (the ray heading almost straight away
            // from the nearest surface) puts it behind the previous sample,
            // whose own distance already counted there, with a side
            // distance near 0 that would darken the pixel. Otherwise use
            // this sample's own distance.
            real y = h < R(2.0) * prev_h ? h * h / (R(2.0) * prev_h) : R(0.0);
            y = y < prev_step ? y : R(0.0);
            real side = sqrt(fmax(h * h - y * y, R(0.0)));
            visible = fmin(visible, side / (softness * fmax(t - y, REAL_TINY)));
            prev_h = h;
            if (visible < faint) {
                return R(0.0);
            }
        }
        real step = fmax(h, eps);
        t += step;
        prev_step = step;
    }
    visible = clamp(visible, R(0.0), R(1.0));
    return visible * visible * (R(3.0) - R(2.0) * visible);
}

// Orbit-trap tint: a cosine palette that fades to white as the trap reaches
// 1, so non-fractal surfaces (trap 1) keep their colour exactly.
real3 march_trap_tint(real trap) {
    real t = clamp(trap, R(0.0), R(1.0));
    real3 phase = (real3)(R(0.0), R(0.1), R(0.2)) + t;
    real3 palette = R(0.5) + R(0.5) * cos(R(6.28318530717958648) * phase);
    return mix(palette, (real3)(R(1.0)), t);
}

// Background at image row py: SKY_BOTTOM at the bottom, SKY_TOP at the top.
real3 march_background(const MarchCamera* cam, real py) {
    real v = clamp(R(1.0) - py / cam->image_h, R(0.0), R(1.0));
    return mix(SKY_BOTTOM, SKY_TOP, v);
}


// Ambient occlusion at p from the distance estimate (see
// march_ambient_occlusion), or 1 without it; the image is view_height
// scene units high at p's distance. The samples lie at offset (0.5: the
// midpoints) of their intervals along the normal. Adds its evaluations to
// *evals.
real march_occlusion(real3 p, real3 n, real view_height, real offset,
                     __global const real* params, uint* evals) {
    real occlusion = R(1.0);
    occlusion = march_ambient_occlusion(p, n, view_height, offset, params);
    *evals += (uint)AO_SAMPLES;
    return occlusion;
}

// The light l (LIGHT_STRIDE reals of the light buffer) as seen from p:
// the unit direction towards it, how far it is (MAX_DISTANCE for a
// directional light) and the radiance that arrives (a point light's falls
// off with the squared distance). Sphere and rectangle lights are taken
// for point lights at their centres, a rectangle lighting its own side
// only, dimmed by the cosine it is seen at (paths.cl samples their
// areas).
real3 march_light(__global const real* l, real3 p, real3* to_light, real* light_distance) {
    real3 v = vload3(0, l + LIGHT_POSITION);
    real3 radiance = vload3(0, l + LIGHT_RADIANCE);
    *to_light = v;
    *light_distance = MAX_DISTANCE;
    if (l[LIGHT_KIND] > R(0.5)) {
        real3 delta = v - p;
        real dist2 = fmax(dot(delta, delta), REAL_TINY);
        *light_distance = sqrt(dist2);
        *to_light = delta / *light_distance;
        radiance /= dist2;
        if (l[LIGHT_KIND] > R(2.5)) {
            // A rectangle lights its own side, dimming with the angle.
            real3 face = cross(normalize(vload3(0, l + LIGHT_EDGE_U)),
                               normalize(vload3(0, l + LIGHT_EDGE_V)));
            radiance *= fmax(dot(face, -*to_light), R(0.0));
        }
    }
    return radiance;
}



// Lit colour of the surface point p with normal n, seen along rd, with the
// sky's light scaled by occlusion (1: open). Adds its distance evaluations
// (DE_shade, DE_material, shadow rays, thickness) to *evals.
//
// Every light adds albedo * diffuse * n.l plus the Blinn-Phong highlight
// specular * (n.h)^shininess * n.l, the diffuse term being Lambert's (1)
// or, with a material's roughness, Oren-Nayar's. With a material's
// subsurface strength s, a light behind the surface (n.l < 0) adds
// albedo * s * thinness * -n.l: it shows through thin parts, unshadowed
// (the shape itself stands between). A material's emission, albedo *
// emission, is not in the lit colour: it goes to *emitted (0 without
// materials), which no share of reflection or transparency dims. Without
// materials the highlight is MARCH_SPECULAR and MARCH_SHININESS, the
// default material's.
real3 march_shade(real3 p, real3 n, real3 rd, real eps, real occlusion,
                  __global const real* params, __global const real* lights, int light_count,
                  __global const float* environment, real3* emitted, uint* evals) {
    *emitted = (real3)(R(0.0));
    real3 albedo;
    real2 trap;
    DE_shade(p, params, &albedo, &trap);
    *evals += 1u;
    albedo *= march_trap_tint(trap.x);
    real specular_strength = MARCH_SPECULAR;
    real shininess = MARCH_SHININESS;

    real3 sky = mix(SKY_BOTTOM, SKY_TOP, R(0.5) + R(0.5) * n.y);
    real3 color = albedo * sky * (MARCH_AMBIENT * occlusion);

    // Shadow rays start one hit threshold off the surface and are blocked
    // within a quarter of it, so a surface does not shadow itself.
    real3 lifted = p + n * eps;
    for (int i = 0; i < light_count; ++i) {
        __global const real* l = lights + LIGHT_STRIDE * i;
        real3 to_light;
        real light_distance;
        real3 radiance = march_light(l, p, &to_light, &light_distance);
        real ndl = dot(n, to_light);
        if (ndl <= R(0.0)) {
            continue;
        }
        real diffuse = R(1.0);
        // The most this light adds to the pixel in any channel.
        real3 most = radiance * ((albedo * diffuse + specular_strength) * ndl);
        real visible = march_shadow(lifted, to_light, light_distance, R(0.25) * eps, eps,
                                    l[LIGHT_SOFTNESS], fmax(most.x, fmax(most.y, most.z)),
                                    params, evals);
        if (visible <= R(0.0)) {
            continue;
        }
        radiance *= visible;
        real3 half_vector = normalize(to_light - rd);
        real specular = specular_strength * pow(fmax(dot(n, half_vector), R(0.0)), shininess);
        color += radiance * (albedo * (diffuse * ndl) + specular * ndl);
    }
    return color;
}

// The shading layers of the surface point p with normal n (see
// codegen::interface::layer): its albedo with the orbit-trap tint, the
// trap's value (1 on surfaces that are not fractals; on a fractal a palette
// paints, the trap its palette reads), and how lit it is: each
// light that faces it weighted by the brightest channel of its radiance
// times n.l, its shadow ray's visibility averaged (1 without shadows, or
// with no light facing it). Shadow rays leave as march_shade's do.
void march_layers(real3 p, real3 n, real eps, __global const real* params,
                  __global const real* lights, int light_count, real3* albedo, real* trap,
                  real* shadow) {
    real2 traps;
    DE_shade(p, params, albedo, &traps);
    *albedo *= march_trap_tint(traps.x);
    *trap = traps.y;
    real lit = R(0.0);
    real weights = R(0.0);
    uint evals = 0u;
    for (int i = 0; i < light_count; ++i) {
        __global const real* l = lights + LIGHT_STRIDE * i;
        real3 to_light;
        real light_distance;
        real3 radiance = march_light(l, p, &to_light, &light_distance);
        real weight = fmax(radiance.x, fmax(radiance.y, radiance.z)) * dot(n, to_light);
        if (weight <= R(0.0)) {
            continue;
        }
        real visible = R(1.0);
        visible = march_shadow(p + n * eps, to_light, light_distance, R(0.25) * eps, eps,
                               l[LIGHT_SOFTNESS], R(1.0), params, &evals);
        lit += weight * visible;
        weights += weight;
    }
    *shadow = weights > R(0.0) ? lit / weights : R(1.0);
}
// optics.cl — reflections and transparency, and where each sample looks.
//
// Follows shade.cl: the branching paths of reflective and transparent
// materials (ENABLE_MATERIALS), the per-sample jitter, the pixel and lens
// points of supersampling and depth of field, and the camera ray of a
// sample.


// Deterministic per-sample jitter in [0, 1): the same image every run.
uint march_hash(uint x) {
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return x;
}

real march_jitter(uint x, uint y, uint sample) {
    uint h = march_hash(x ^ march_hash(y ^ march_hash(sample)));
    return (real)(h >> 8) * R(5.9604644775390625e-8); // 2^-24
}

// Point j of the R2 sequence (Roberts 2018), rotated by a per-pixel
// offset from the hash: well spread in the pixel for every count of
// points, so progressive passes converge faster than independent random
// points would. The steps are 1 / g and 1 / g^2 for g the root of
// x^3 = x + 1, as 32-bit fractions: j times a step wraps to its
// fractional part exactly, in any precision.
real2 march_pixel_point(uint pixel, uint j) {
    uint2 steps = ((uint2)(0xc13fa9a9u, 0x91e10da6u) * j) >> 8;
    real2 q = (real2)(march_jitter(pixel, 0u, 0u), march_jitter(pixel, 0u, 1u))
              + (real2)((real)steps.x, (real)steps.y) * R(5.9604644775390625e-8); // 2^-24
    return q - floor(q);
}

// The radical inverse of j in base b: its digits mirrored about the point.
real march_radical_inverse(uint j, uint b) {
    real step = R(1.0) / (real)b;
    real scale = step;
    real r = R(0.0);
    for (; j > 0u; j /= b) {
        r += scale * (real)(j % b);
        scale *= step;
    }
    return r;
}

// Point j of the Halton sequence in bases 2 and 3, rotated by a per-pixel
// offset from the hash: where sample j leaves the lens, in the unit
// square. A different kind of sequence from the pixel's, so no point in
// the pixel is tied to one on the lens, and pixel and lens together are
// well spread too.
real2 march_lens_point(uint pixel, uint j) {
    real2 q = (real2)(march_jitter(pixel, 0u, 2u), march_jitter(pixel, 0u, 3u))
              + (real2)(march_radical_inverse(j, 2u), march_radical_inverse(j, 3u));
    return q - floor(q);
}

// The unit square onto the unit disc, keeping areas and neighbourhoods
// (Shirley and Chiu's concentric map).
real2 march_disc(real2 q) {
    real a = R(2.0) * q.x - R(1.0);
    real b = R(2.0) * q.y - R(1.0);
    if (a == R(0.0) && b == R(0.0)) {
        return (real2)(R(0.0));
    }
    const real quarter = R(0.78539816339744831);
    if (fabs(a) > fabs(b)) {
        return a * (real2)(cos(quarter * b / a), sin(quarter * b / a));
    }
    return b * (real2)(sin(quarter * a / b), cos(quarter * a / b));
}

// Where sample j of a pixel (j = pass * SUPERSAMPLING^2 + s) lies in it,
// (jx, jy) in [0, 1)^2. With supersampling, sample s is jittered in cell s
// of an N x N grid over the pixel; without, sample 0 is the pixel's centre
// and the rest follow the R2 sequence. (On the lens, the sample lies at
// march_disc(march_lens_point(pixel, j)).)
void march_sample_point(uint pixel, uint j, int s, real* jx, real* jy) {
    if (SUPERSAMPLING > 1) {
        *jx = ((real)(s % SUPERSAMPLING) + march_jitter(pixel, j, 0u)) / (real)SUPERSAMPLING;
        *jy = ((real)(s / SUPERSAMPLING) + march_jitter(pixel, j, 1u)) / (real)SUPERSAMPLING;
    } else if (j == 0u) {
        *jx = R(0.5);
        *jy = R(0.5);
    } else {
        real2 q = march_pixel_point(pixel, j);
        *jx = q.x;
        *jy = q.y;
    }
}

// The ray of sample j (the s-th of its pass) of rendered pixel (x, y),
// whose index is pixel: its image row *py, origin and direction.
void march_sample_ray(const MarchCamera* cam, int x, int y, uint pixel, uint j, int s, real* py,
                      real3* ro, real3* rd) {
    real jx;
    real jy;
    march_sample_point(pixel, j, s, &jx, &jy);
    // A pinhole needs no lens point.
    real2 lens = (real2)(R(0.0));
    if (cam->aperture > R(0.0)) {
        lens = march_disc(march_lens_point(pixel, j));
    }
    // Rendered pixel (x, y) covers pixel_scale image pixels each way.
    real px = ((real)x + jx) * cam->pixel_scale;
    *py = ((real)y + jy) * cam->pixel_scale;
    march_lens_ray(cam, px, *py, lens, ro, rd);
}
// paths.cl — path-traced global illumination (ENABLE_GI).
//
// Follows optics.cl: each sample's first hit starts a path that bounces
// through the scene, sampling the lights at every surface it meets and
// bringing the sky's light where it leaves (quality::GlobalIllumination).
//
// Units: a light's radiance is the light a white Lambertian surface facing
// it sends back, as in direct lighting, so a surface lit by one light has
// the same colour in both modes; its irradiance is pi times that. The sky
// along a direction is a radiance: under a sky of 1 everywhere, a white
// surface is 1 (the white furnace).

// render.cl — the kernels a render program runs.
//
// Follows paths.cl: the brute-force depth pass of inside shapes
// (ENABLE_BRUTE), the screen-space normals and occlusion of stored depths,
// render_tile (one tile of pixels: march, shade, fog and glow) and the
// coarse pass (ENABLE_CONE: cone_starts).


// One launch shades the tile [x0, x0 + tile_w) x [y0, y0 + tile_h) of a
// width x height image. The global size may be rounded up past the tile.
//
// A frame of its own (pass < 0) takes SUPERSAMPLING^2 samples per pixel.
// Progressive pass k >= 0 takes the next SUPERSAMPLING^2 (samples
// k N^2 to (k + 1) N^2 - 1), adds their linear colours to the pixel's sum
// in accumulation (pass 0 starts it) and writes the mean of every sample
// so far: pass 0 is the frame of its own, and later passes converge on
// the mean of ever more samples. With refine_only, only the pixels refine
// marks take the pass: adaptive supersampling refines edges alone.
//
// AOVs describe the ray through the pixel centre and the lens's centre:
// depth (distance along the ray, +INFINITY on a miss), hit (0/1),
// world-space normal (0 on a miss); and the cost of the pixel's colour:
// steps, the primary-march distance evaluations of this launch's samples,
// and evaluations, every distance evaluation of them (primary march,
// normal, DE_shade, occlusion and shadow rays, and the step onto the
// surface of a ray that starts inside it). The extra march through the
// pixel centre that AOVs need with supersampling or a lens is not counted,
// nor are the shading layers' evaluations.
//
// With write_aovs at WRITE_LAYERS, every pass also writes linear: the
// colour before the display transform (exposed, not clipped) and the
// fraction of the samples that hit; and the first pass the shading
// layers of the centre ray's hit (codegen::interface::layer).
__kernel void render_tile(RENDER_TILE_ARGS) {
    int lx = (int)get_global_id(0);
    int ly = (int)get_global_id(1);
    int x = x0 + lx;
    int y = y0 + ly;
    if (lx >= tile_w || ly >= tile_h || x >= width || y >= height) {
        return;
    }
    if (refine_only && !refine[y * width + x]) {
        return;
    }
    MarchCamera cam = march_load_camera(camera);
    // Where the pixel's rays start: past the empty space the coarse pass
    // found in front of its tile.
    real start = R(0.0);

    const int per_pass = SUPERSAMPLING * SUPERSAMPLING;
    const uint first = pass > 0 ? (uint)pass * (uint)per_pass : 0u;
    const uint pixel = (uint)y * (uint)width + (uint)x;
    real3 sum = (real3)(R(0.0));
    uint total_steps = 0;
    uint total_evals = 0;
    uint hits = 0;
    MarchResult centre = {R(0.0), R(1.0), 0, 0};
    real3 centre_normal = (real3)(R(0.0));
    // The ray the AOVs describe: the first sample's, or the pixel centre's.
    real3 centre_ro = (real3)(R(0.0));
    real3 centre_rd = (real3)(R(0.0));
    // Whether the rays come marched by brute_depths.
    int stored = 0;
    for (int s = 0; s < per_pass; ++s) {
        const uint j = first + (uint)s;
        real py;
        real3 ro;
        real3 rd;
        march_sample_ray(&cam, x, y, pixel, j, s, &py, &ro, &rd);
        MarchResult m;
        if (!stored) {
            m = march_ray(ro, rd, start, &cam, R(1.0), params);
        }
        total_steps += (uint)m.steps;
        total_evals += (uint)m.steps;

        real3 background = march_background(&cam, py);
        real3 color = background;
        real3 n = (real3)(R(0.0));
        if (m.hit) {
            hits += 1u;
            real3 p = ro + rd * m.t;
            real footprint = march_footprint(&cam, m.t);
            real view_height = footprint * cam.image_h;
            // Whether p lies in an inside shape, which has no distance to
            // take a normal or occlusion from.
            int in_set = 0;
            if (!in_set) {
                n = march_normal(p, NORMAL_EPSILON * footprint, rd, params);
                total_evals += MARCH_NORMAL_EVALUATIONS;
                if (m.t > R(0.0)) {
                    n = march_facing(n, rd);
                } else {
                    // The ray starts inside the surface (a camera within a
                    // solid): shade the nearest point of the surface
                    // instead. No view to scale occlusion to: it keeps
                    // AO_DISTANCE.
                    p -= n * DE(p, params);
                    total_evals += 1u;
                    view_height = (real)INFINITY;
                }
            }
            // Occlusion samples at the midpoints of their intervals.
            real offset = R(0.5);
            real occlusion = march_occlusion(p, n, view_height, offset, params, &total_evals);
            real3 emitted;
            color = march_shade(p, n, rd, DETAIL * footprint, occlusion, params, lights,
                                light_count, environment, &emitted, &total_evals);
        }
        sum += color;
        if (s == 0) {
            centre = m;
            centre_normal = n;
            centre_ro = ro;
            centre_rd = rd;
        }
    }
    int idx = y * width + x;
    real3 color = sum / (real)per_pass;
    real coverage = (real)hits / (real)per_pass;
    if (pass >= 0) {
        // The spare fourth float sums the samples that hit.
        float4 total = pass == 0 ? (float4)(0.0f) : accumulation[idx];
        total += (float4)(convert_float3(sum), (float)hits);
        accumulation[idx] = total;
        if (pass > 0) {
            real samples = (real)(pass + 1) * (real)per_pass;
            color = (real3)(total.x, total.y, total.z) / samples;
            coverage = (real)total.w / samples;
        }
    }
    if (write_aovs >= WRITE_LAYERS) {
        linear[idx] = (float4)(convert_float3(color * EXPOSURE_SCALE), (float)coverage);
    }
    real3 out = display_color(color, EXPOSURE_SCALE, R(1.0) / GAMMA);
    rgba[idx] = (uchar4)(convert_uchar3_sat_rte(convert_float3(out) * 255.0f), (uchar)255);

    // Later passes leave the outputs of the first: the same rays.
    if (write_aovs && pass <= 0) {
        // The colour samples are jittered: trace the pixel centre. Brute
        // forced rays report their first sample's instead: its normal
        // needs the neighbours' samples.
        int jittered = SUPERSAMPLING > 1 || cam.aperture > R(0.0);
        if (jittered && !stored) {
            real3 ro;
            real3 rd;
            march_camera_ray(&cam, ((real)x + R(0.5)) * cam.pixel_scale,
                             ((real)y + R(0.5)) * cam.pixel_scale, &ro, &rd);
            centre_ro = ro;
            centre_rd = rd;
            centre = march_ray(ro, rd, start, &cam, R(1.0), params);
            centre_normal = (real3)(R(0.0));
            if (centre.hit) {
                real h = NORMAL_EPSILON * march_footprint(&cam, centre.t);
                centre_normal = march_normal(ro + rd * centre.t, h, rd, params);
                if (centre.t > R(0.0)) {
                    centre_normal = march_facing(centre_normal, rd);
                }
            }
        }
        if (write_aovs >= WRITE_LAYERS) {
            // What the centre ray's hit is made of (0 on a miss).
            __global float* layer = layers + LAYER_STRIDE * idx;
            real3 position = (real3)(R(0.0));
            real3 albedo = (real3)(R(0.0));
            real occlusion = R(0.0);
            real trap = R(0.0);
            real shadow = R(0.0);
            if (centre.hit) {
                real footprint = march_footprint(&cam, centre.t);
                position = centre_ro + centre_rd * centre.t;
                uint uncounted = 0u;
                if (centre.t <= R(0.0) && !stored) {
                    // A ray that starts inside a solid: the point shaded
                    // is the nearest of the surface, as for the colour.
                    position -= centre_normal * DE(position, params);
                }
                occlusion = march_occlusion(position, centre_normal, footprint * cam.image_h,
                                            R(0.5), params, &uncounted);
                march_layers(position, centre_normal, DETAIL * footprint, params, lights,
                             light_count, &albedo, &trap, &shadow);
            }
            vstore3(convert_float3(position), 0, layer + LAYER_POSITION);
            vstore3(convert_float3(albedo), 0, layer + LAYER_ALBEDO);
            layer[LAYER_OCCLUSION] = (float)occlusion;
            layer[LAYER_SHADOW] = (float)shadow;
            layer[LAYER_TRAP] = (float)trap;
        }
        depth[idx] = centre.hit ? (float)centre.t : INFINITY;
        hit_mask[idx] = (uchar)centre.hit;
        vstore3(convert_float3(centre_normal), idx, normals);
        steps[idx] = total_steps;
        evaluations[idx] = total_evals;
    }
}

