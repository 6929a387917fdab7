// march.cl — the reusable sphere tracer and shading.
//
// Appended after the generated header and the scene's distance functions.
// It uses only:
//   types   real, real2, real3, real4 and the literal macro R(x)
//   consts  REAL_TINY MAX_STEPS MAX_DISTANCE HIT_EPSILON NORMAL_EPSILON
//           OVER_RELAXATION SUPERSAMPLING GAMMA SKY_TOP SKY_BOTTOM
//   scene   real DE(real3 p, __global const real* params)
//           real DE_shade(real3 p, __global const real* params,
//                         real3* color, real* trap)
//   effects: the code of each effect (ambient occlusion, shadows, glow,
//           fog) sits in a conditional block named ENABLE_<effect>, with
//           its constants defined by the header only when it is on. Code
//           generation resolves these blocks itself and leaves out every
//           effect that is off, so they are the only preprocessor
//           conditionals allowed in this file.
//
// Everything else arrives at run time, so moving the camera or the lights
// and changing dynamic parameters never rebuilds the program:
//
// camera: 20 reals
//   [0..2]  origin          [3]  1 for orthographic, 0 for perspective
//   [4..6]  right (unit)    [7]  half the image width at unit distance
//                                (orthographic: in scene units)
//   [8..10] up (unit)       [11] half the image height, likewise
//   [12..14] forward (unit) [15] unused
//   [16] footprint_base  [17] footprint_per_unit
//        A pixel is footprint_base + footprint_per_unit * t scene units
//        wide at distance t along a ray. Perspective cameras have a
//        per-unit term and a tiny base that keeps thresholds above zero at
//        t = 0; orthographic cameras have only the base.
//   [18..19] unused
//
// lights: 8 reals per light
//   [0..2] unit direction towards the light, or the light's position
//   [3]    0 directional, 1 point (1/r^2 falloff)
//   [4..6] colour * intensity (linear RGB)
//   [7]    penumbra softness (0: hard shadows)

// Shading constants that are not quality knobs.
#define MARCH_AMBIENT R(0.5)      // strength of the sky's hemisphere light
#define MARCH_SPECULAR R(0.25)    // Blinn-Phong specular strength
#define MARCH_SHININESS R(32.0)   // Blinn-Phong exponent
#define MARCH_NORMAL_EVALUATIONS 4u // DE calls of march_normal
#ifdef ENABLE_GLOW
#define MARCH_GLOW_FALLOFF R(24.0) // glow ~ exp(-falloff * closest angle)
#endif

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
    int orthographic;
} MarchCamera;

MarchCamera march_load_camera(__global const real* c) {
    MarchCamera cam;
    cam.origin = (real3)(c[0], c[1], c[2]);
    cam.orthographic = c[3] > R(0.5);
    cam.right = (real3)(c[4], c[5], c[6]);
    cam.half_w = c[7];
    cam.up = (real3)(c[8], c[9], c[10]);
    cam.half_h = c[11];
    cam.forward = (real3)(c[12], c[13], c[14]);
    cam.footprint_base = c[16];
    cam.footprint_per_unit = c[17];
    return cam;
}

// Scene units covered by one pixel at distance t along a ray.
real march_footprint(const MarchCamera* cam, real t) {
    return cam->footprint_base + cam->footprint_per_unit * t;
}

// The ray through image position (px, py) in pixels, (0, 0) being the top
// left corner of the image.
void march_camera_ray(const MarchCamera* cam, real px, real py, int width, int height,
                      real3* ro, real3* rd) {
    real u = (R(2.0) * px / (real)width - R(1.0)) * cam->half_w;
    real v = (R(1.0) - R(2.0) * py / (real)height) * cam->half_h;
    if (cam->orthographic) {
        *ro = cam->origin + cam->right * u + cam->up * v;
        *rd = cam->forward;
    } else {
        *ro = cam->origin;
        *rd = normalize(cam->forward + cam->right * u + cam->up * v);
    }
}

// Sphere tracing. A hit is a distance below HIT_EPSILON pixel footprints.
// With OVER_RELAXATION > 1 the steps are lengthened (Keinert et al. 2014);
// when the unbounding spheres of two consecutive points stop overlapping
// the long step may have jumped over a surface, so the march returns to the
// last safe point and continues with plain steps.
MarchResult march_ray(real3 ro, real3 rd, const MarchCamera* cam,
                      __global const real* params) {
    MarchResult r;
    r.t = R(0.0);
    r.closest = R(1.0);
    r.steps = 0;
    r.hit = 0;
    real omega = OVER_RELAXATION;
    real prev_t = R(0.0);
    real prev_d = R(0.0);
    for (int i = 0; i < MAX_STEPS; ++i) {
        real d = DE(ro + rd * r.t, params);
        r.steps = i + 1;
        if (omega > R(1.0) && i > 0 && (d < R(0.0) || d + prev_d < r.t - prev_t)) {
            r.t = prev_t + prev_d;
            omega = R(1.0);
            continue;
        }
        if (d > R(0.0)) {
            r.closest = fmin(r.closest, d / (r.t + d));
        }
        if (d < HIT_EPSILON * march_footprint(cam, r.t)) {
            r.hit = 1;
            r.closest = R(0.0);
            return r;
        }
        prev_t = r.t;
        prev_d = d;
        r.t += omega * d;
        if (r.t > MAX_DISTANCE) {
            return r;
        }
    }
    return r;
}

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

#ifdef ENABLE_AO
// Ambient occlusion: how much closer the surface is than expected at
// AO_SAMPLES points along the normal, nearer samples weighing more.
// 1 on an open face, towards 0 in a crease.
// Evaluates DE AO_SAMPLES times.
real march_ambient_occlusion(real3 p, real3 n, __global const real* params) {
    real missing = R(0.0);
    real expected = R(0.0);
    real weight = R(1.0);
    for (int i = 1; i <= AO_SAMPLES; ++i) {
        real h = AO_STEP * (real)i;
        real d = DE(p + n * h, params);
        missing += weight * clamp(h - d, R(0.0), h);
        expected += weight * h;
        weight *= R(0.75);
    }
    return clamp(R(1.0) - missing / expected, R(0.0), R(1.0));
}
#endif

#ifdef ENABLE_SHADOWS
// Visibility of a light from ro along rd, from distance start to max_t: 0
// in full shadow, 1 fully lit. softness 0 gives a hard shadow; above 0,
// Quilez's improved soft shadow (2018) with a penumbra that grows with
// softness. The ray is blocked where it comes within eps of a surface;
// callers pass a fraction of the surface hit threshold so shadows are not
// fattened by a pixel where objects nearly touch. Adds its DE evaluations
// to *evals.
real march_shadow(real3 ro, real3 rd, real max_t, real eps, real start, real softness,
                  __global const real* params, uint* evals) {
    real visible = R(1.0);
    real prev_h = R(1e20);
    real t = start;
    for (int i = 0; i < SHADOW_STEPS && t < max_t; ++i) {
        real h = DE(ro + rd * t, params);
        *evals += 1u;
        if (h < eps) {
            return R(0.0);
        }
        if (softness > R(0.0)) {
            // The closest point to the surface between this sample and the
            // previous one, estimated from the two distance spheres. They
            // cross only if h < 2 prev_h, always true of an exact distance
            // but not of every estimator (or after a minimum-length step);
            // otherwise use this sample's own distance.
            real y = h < R(2.0) * prev_h ? h * h / (R(2.0) * prev_h) : R(0.0);
            real side = sqrt(fmax(h * h - y * y, R(0.0)));
            visible = fmin(visible, side / (softness * fmax(t - y, REAL_TINY)));
            prev_h = h;
        }
        t += fmax(h, eps);
    }
    visible = clamp(visible, R(0.0), R(1.0));
    return visible * visible * (R(3.0) - R(2.0) * visible);
}
#endif

// Orbit-trap tint: a cosine palette that fades to white as the trap reaches
// 1, so non-fractal surfaces (trap 1) keep their colour exactly.
real3 march_trap_tint(real trap) {
    real t = clamp(trap, R(0.0), R(1.0));
    real3 phase = (real3)(R(0.0), R(0.1), R(0.2)) + t;
    real3 palette = R(0.5) + R(0.5) * cos(R(6.28318530717958648) * phase);
    return mix(palette, (real3)(R(1.0)), t);
}

// Background at image row py: SKY_BOTTOM at the bottom, SKY_TOP at the top.
real3 march_background(real py, int height) {
    real v = clamp(R(1.0) - py / (real)height, R(0.0), R(1.0));
    return mix(SKY_BOTTOM, SKY_TOP, v);
}

// Lit colour of the surface point p with normal n, seen along rd. Adds its
// distance evaluations (DE_shade, occlusion, shadow rays) to *evals.
real3 march_shade(real3 p, real3 n, real3 rd, real eps, __global const real* params,
                  __global const real* lights, int light_count, uint* evals) {
    real3 albedo;
    real trap;
    DE_shade(p, params, &albedo, &trap);
    *evals += 1u;
    albedo *= march_trap_tint(trap);

    real occlusion = R(1.0);
#ifdef ENABLE_AO
    occlusion = march_ambient_occlusion(p, n, params);
    *evals += (uint)AO_SAMPLES;
#endif
    real3 sky = mix(SKY_BOTTOM, SKY_TOP, R(0.5) + R(0.5) * n.y);
    real3 color = albedo * sky * (MARCH_AMBIENT * occlusion);

#ifdef ENABLE_SHADOWS
    // Shadow rays start one hit threshold off the surface and are blocked
    // within a quarter of it, so a surface does not shadow itself.
    real3 lifted = p + n * eps;
#endif
    for (int i = 0; i < light_count; ++i) {
        __global const real* l = lights + 8 * i;
        real3 v = (real3)(l[0], l[1], l[2]);
        real3 radiance = (real3)(l[4], l[5], l[6]);
        real3 to_light = v;
        real light_distance = MAX_DISTANCE;
        if (l[3] > R(0.5)) {
            real3 delta = v - p;
            real dist2 = fmax(dot(delta, delta), REAL_TINY);
            light_distance = sqrt(dist2);
            to_light = delta / light_distance;
            radiance /= dist2;
        }
        real ndl = dot(n, to_light);
        if (ndl <= R(0.0)) {
            continue;
        }
#ifdef ENABLE_SHADOWS
        real visible =
            march_shadow(lifted, to_light, light_distance, R(0.25) * eps, eps, l[7], params, evals);
        if (visible <= R(0.0)) {
            continue;
        }
        radiance *= visible;
#endif
        real3 half_vector = normalize(to_light - rd);
        real specular = MARCH_SPECULAR * pow(fmax(dot(n, half_vector), R(0.0)), MARCH_SHININESS);
        color += radiance * (albedo * ndl + specular * ndl);
    }
    return color;
}

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

// One launch shades the tile [x0, x0 + tile_w) x [y0, y0 + tile_h) of a
// width x height image. The global size may be rounded up past the tile.
//
// AOVs describe the ray through the pixel centre: depth (distance along
// the ray, +INFINITY on a miss), hit (0/1), world-space normal (0 on a
// miss); and the cost of the pixel's colour: steps, the primary-march
// distance evaluations of all its samples, and evaluations, every distance
// evaluation of all its samples (primary march, normal, the step onto the
// surface, DE_shade, occlusion and shadow rays). The extra march through
// the pixel centre that AOVs need with supersampling is not counted.
__kernel void render_tile(__global const real* params,
                          __global const real* camera,
                          __global const real* lights,
                          const int light_count,
                          const int width,
                          const int height,
                          const int x0,
                          const int y0,
                          const int tile_w,
                          const int tile_h,
                          const int write_aovs,
                          __global uchar4* rgba,
                          __global float* depth,
                          __global uchar* hit_mask,
                          __global float* normals,
                          __global uint* steps,
                          __global uint* evaluations) {
    int lx = (int)get_global_id(0);
    int ly = (int)get_global_id(1);
    int x = x0 + lx;
    int y = y0 + ly;
    if (lx >= tile_w || ly >= tile_h || x >= width || y >= height) {
        return;
    }
    MarchCamera cam = march_load_camera(camera);

    real3 sum = (real3)(R(0.0));
    uint total_steps = 0;
    uint total_evals = 0;
    MarchResult centre = {R(0.0), R(1.0), 0, 0};
    real3 centre_normal = (real3)(R(0.0));
    for (int s = 0; s < SUPERSAMPLING * SUPERSAMPLING; ++s) {
        real jx = R(0.5);
        real jy = R(0.5);
        if (SUPERSAMPLING > 1) {
            uint pixel = (uint)y * (uint)width + (uint)x;
            jx = ((real)(s % SUPERSAMPLING) + march_jitter(pixel, (uint)s, 0u))
                 / (real)SUPERSAMPLING;
            jy = ((real)(s / SUPERSAMPLING) + march_jitter(pixel, (uint)s, 1u))
                 / (real)SUPERSAMPLING;
        }
        real px = (real)x + jx;
        real py = (real)y + jy;
        real3 ro;
        real3 rd;
        march_camera_ray(&cam, px, py, width, height, &ro, &rd);
        MarchResult m = march_ray(ro, rd, &cam, params);
        total_steps += (uint)m.steps;
        total_evals += (uint)m.steps;

        real3 background = march_background(py, height);
        real3 color = background;
        real3 n = (real3)(R(0.0));
        if (m.hit) {
            real3 p = ro + rd * m.t;
            real footprint = march_footprint(&cam, m.t);
            n = march_normal(p, NORMAL_EPSILON * footprint, rd, params);
            // The march stopped up to a hit threshold short of the surface:
            // step onto it along the normal so secondary rays start there.
            p -= n * DE(p, params);
            total_evals += MARCH_NORMAL_EVALUATIONS + 1u;
            color = march_shade(p, n, rd, HIT_EPSILON * footprint, params, lights, light_count,
                                &total_evals);
#ifdef ENABLE_FOG
            color = mix(background, color, exp(-FOG_DENSITY * m.t));
#endif
        }
#ifdef ENABLE_GLOW
        else {
            color += GLOW_COLOR * (GLOW_STRENGTH * exp(-MARCH_GLOW_FALLOFF * m.closest));
        }
#endif
        sum += color;
        if (s == 0) {
            centre = m;
            centre_normal = n;
        }
    }
    real3 color = sum / (real)(SUPERSAMPLING * SUPERSAMPLING);
    real3 out = pow(clamp(color, R(0.0), R(1.0)), (real3)(R(1.0) / GAMMA));
    int idx = y * width + x;
    rgba[idx] = (uchar4)(convert_uchar3_sat_rte(convert_float3(out) * 255.0f), (uchar)255);

    if (write_aovs) {
        if (SUPERSAMPLING > 1) {
            // The colour samples are jittered: trace the pixel centre.
            real3 ro;
            real3 rd;
            march_camera_ray(&cam, (real)x + R(0.5), (real)y + R(0.5), width, height, &ro, &rd);
            centre = march_ray(ro, rd, &cam, params);
            centre_normal = (real3)(R(0.0));
            if (centre.hit) {
                real h = NORMAL_EPSILON * march_footprint(&cam, centre.t);
                centre_normal = march_normal(ro + rd * centre.t, h, rd, params);
            }
        }
        depth[idx] = centre.hit ? (float)centre.t : INFINITY;
        hit_mask[idx] = (uchar)centre.hit;
        vstore3(convert_float3(centre_normal), idx, normals);
        steps[idx] = total_steps;
        evaluations[idx] = total_evals;
    }
}
