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

#ifdef ENABLE_AO
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
#endif

#ifdef ENABLE_SHADOWS
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
#ifdef ENABLE_SCENE_BOUND
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
#endif
#ifdef ENABLE_BRUTE
    // Inside shapes block the ray where a sample lands in them: samples
    // BRUTE_STEP times 4 of the shaded pixel's footprints apart (start is
    // DETAIL footprints), beyond SHADOW_STEPS. They begin two samples out:
    // a set's surface is rough at the scale of a step, and the sub-pixel
    // dust next to a hit would otherwise shadow every point of it.
    const real lattice = R(4.0) * BRUTE_STEP * start / DETAIL;
    real2 span = march_brute_span(ro, rd);
    span.x = fmax(span.x, R(2.0) * lattice);
    real next_sample = R(-1.0);
    int brute_steps = 0;
#endif
    for (int i = 0; i < SHADOW_STEPS && t < max_t; ++i) {
        real h = DE(ro + rd * t, params);
        *evals += 1u;
#ifdef ENABLE_BRUTE
        if (h <= R(-0.5) * INSIDE_HUGE && t < span.x) {
            // The dust next to the start: no information.
            h = INSIDE_HUGE;
        }
#endif
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
#ifdef ENABLE_BRUTE
        real brute = march_brute_step(t, step, span, lattice, R(0.5), &next_sample);
        if (brute < step) {
            step = brute;
            if (brute_steps < BRUTE_MAX_STEPS) {
                brute_steps += 1;
                i -= 1;
            }
        }
#endif
        t += step;
        prev_step = step;
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
real3 march_background(const MarchCamera* cam, real py) {
    real v = clamp(R(1.0) - py / cam->image_h, R(0.0), R(1.0));
    return mix(SKY_BOTTOM, SKY_TOP, v);
}
#ifdef ENABLE_ENVIRONMENT

// The environment light (scene::Environment), from its buffer (the layout
// of codegen::interface::environment): an equirectangular image, direction
// d at u = 1/2 + atan2(d.x, -d.z) / 2 pi across and v = acos(d.y) / pi
// down in the image's own frame, which is the scene's turned by the
// rotation about +Y.
#define MARCH_PI R(3.14159265358979324)

// Texel (x, y) of the w x h image at `at` in the buffer.
real3 march_env_texel(__global const float* env, int at, int w, int x, int y) {
    int i = at + 3 * (y * w + x);
    return (real3)((real)env[i], (real)env[i + 1], (real)env[i + 2]);
}

// The w x h image at `at` at (u, v), bilinear between texel centres,
// wrapping across u and clamped in v (scene::EnvironmentMap::radiance).
real3 march_env_bilinear(__global const float* env, int at, int w, int h, real2 uv) {
    real fx = uv.x * (real)w - R(0.5);
    real fy = clamp(uv.y * (real)h - R(0.5), R(0.0), (real)(h - 1));
    real x0 = floor(fx);
    real y0 = floor(fy);
    real tx = fx - x0;
    real ty = fy - y0;
    int xa = (int)x0 % w;
    xa += xa < 0 ? w : 0;
    int xb = (xa + 1) % w;
    int ya = (int)y0;
    int yb = min(ya + 1, h - 1);
    real3 a = march_env_texel(env, at, w, xa, ya);
    real3 b = march_env_texel(env, at, w, xb, ya);
    real3 c = march_env_texel(env, at, w, xa, yb);
    real3 e = march_env_texel(env, at, w, xb, yb);
    return mix(mix(a, b, tx), mix(c, e, tx), ty);
}

// The image coordinates of the unit direction d.
real2 march_env_uv(__global const float* env, real3 d) {
    real c = (real)env[ENV_ROTATION_COS];
    real s = (real)env[ENV_ROTATION_SIN];
    real3 turned = (real3)(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
    return (real2)(R(0.5) + atan2(turned.x, -turned.z) / (R(2.0) * MARCH_PI),
                   acos(clamp(turned.y, R(-1.0), R(1.0))) / MARCH_PI);
}

// The environment's radiance along the unit direction d, as its texel
// holds it: what lights a surface, constant over each texel as the
// importance sampling of paths.cl draws them.
real3 march_environment_texel(__global const float* env, real3 d) {
    int w = (int)env[ENV_WIDTH];
    int h = (int)env[ENV_HEIGHT];
    real2 uv = march_env_uv(env, d);
    int x = clamp((int)(uv.x * (real)w), 0, w - 1);
    int y = clamp((int)(uv.y * (real)h), 0, h - 1);
    return march_env_texel(env, ENV_TEXELS, w, x, y) * (real)env[ENV_INTENSITY];
}

// The environment's radiance along the unit direction d, bilinear between
// texel centres: what the camera, mirrors and glass show.
real3 march_environment(__global const float* env, real3 d) {
    int w = (int)env[ENV_WIDTH];
    int h = (int)env[ENV_HEIGHT];
    return march_env_bilinear(env, ENV_TEXELS, w, h, march_env_uv(env, d))
           * (real)env[ENV_INTENSITY];
}

// The environment's irradiance on a face turned along the unit normal n,
// over pi: the radiance a white Lambertian face sends back under it,
// unoccluded (precomputed by the host at a few texels).
real3 march_environment_irradiance(__global const float* env, real3 n) {
    int w = (int)env[ENV_WIDTH];
    int h = (int)env[ENV_HEIGHT];
    int at = ENV_TEXELS + 3 * w * h + (h + 1) + h * (w + 1);
    return march_env_bilinear(env, at, (int)env[ENV_IRRADIANCE_WIDTH],
                              (int)env[ENV_IRRADIANCE_HEIGHT], march_env_uv(env, n))
           * (real)env[ENV_INTENSITY];
}
#endif
#ifdef ENABLE_SKY_RAYS

// The sky seen along rd, where a path leaves the scene or is cut off: the
// environment light, or without one SKY_BOTTOM straight down and SKY_TOP
// straight up.
real3 march_sky(real3 rd, __global const float* environment) {
    real3 sky = mix(SKY_BOTTOM, SKY_TOP, clamp(R(0.5) + R(0.5) * rd.y, R(0.0), R(1.0)));
#ifdef ENABLE_ENVIRONMENT
    sky = march_environment(environment, rd);
#endif
    return sky;
}
#endif

#ifdef ENABLE_MATERIALS
#define MARCH_SCATTER_SAMPLES 4 // DE calls of march_thinness

// Oren-Nayar's qualitative model: the diffuse light of a surface of
// microfacets whose slopes spread by sigma radians, relative to Lambert's
// (so 1 at sigma 0), for unit normal n, light direction l and view
// direction v, with ndl = n.l > 0:
//   A + B max(0, cos(phi_l - phi_v)) sin(alpha) tan(beta),
//   A = 1 - sigma^2 / (2 (sigma^2 + 0.33)),  B = 0.45 sigma^2 / (sigma^2 + 0.09),
// alpha and beta the larger and smaller of the angles of l and v from n.
real march_oren_nayar(real sigma, real3 n, real3 l, real3 v, real ndl) {
    if (sigma <= R(0.0)) {
        return R(1.0);
    }
    real s2 = sigma * sigma;
    real a = R(1.0) - R(0.5) * s2 / (s2 + R(0.33));
    real b = R(0.45) * s2 / (s2 + R(0.09));
    // The view can sit just behind a normal taken by differences.
    real ndv = clamp(dot(n, v), R(1e-4), R(1.0));
    real3 lt = l - n * ndl;
    real3 vt = v - n * ndv;
    real norms = length(lt) * length(vt);
    real cos_phi = norms > REAL_TINY ? fmax(dot(lt, vt) / norms, R(0.0)) : R(0.0);
    real cos_alpha = fmin(ndl, ndv);
    real cos_beta = fmax(ndl, ndv);
    real sin_alpha = sqrt(fmax(R(1.0) - cos_alpha * cos_alpha, R(0.0)));
    real tan_beta = sqrt(fmax(R(1.0) - cos_beta * cos_beta, R(0.0))) / cos_beta;
    return a + b * cos_phi * sin_alpha * tan_beta;
}

// How thin the shape is below p, with outward normal n, down to depth:
// 0 where it is solid that deep, towards 1 where it ends sooner. Samples
// MARCH_SCATTER_SAMPLES points along the inward normal; at h below a
// solid face the distance is -h, so each sample adds how far its depth
// inside falls short of h.
real march_thinness(real3 p, real3 n, real depth, __global const real* params, uint* evals) {
    real solid = R(0.0);
    for (int i = 1; i <= MARCH_SCATTER_SAMPLES; ++i) {
        real h = depth * (real)i / (real)MARCH_SCATTER_SAMPLES;
        solid += clamp(-DE(p - n * h, params) / h, R(0.0), R(1.0));
    }
    *evals += (uint)MARCH_SCATTER_SAMPLES;
    return R(1.0) - solid / (real)MARCH_SCATTER_SAMPLES;
}
#endif

// Ambient occlusion at p from the distance estimate (see
// march_ambient_occlusion), or 1 without it; the image is view_height
// scene units high at p's distance. The samples lie at offset (0.5: the
// midpoints) of their intervals along the normal. Adds its evaluations to
// *evals.
real march_occlusion(real3 p, real3 n, real view_height, real offset,
                     __global const real* params, uint* evals) {
    real occlusion = R(1.0);
#ifdef ENABLE_AO
    occlusion = march_ambient_occlusion(p, n, view_height, offset, params);
    *evals += (uint)AO_SAMPLES;
#endif
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

#ifdef ENABLE_FOG
// The fog's optical depth from ro along the unit rd to distance t (which
// may be INFINITY): FOG_DENSITY t for a uniform fog. With FOG_FALLOFF b,
// the density is FOG_DENSITY exp(a) with a = -b (y - FOG_HEIGHT), and
// along the ray a falls by k = b rd.y per unit: the depth is the density's
// fall from ro to the end over k, FOG_DENSITY (exp(a0) - exp(a0 - k t)) / k
// (the density times t, less half its slope's share, where k t is tiny).
// The exponents are capped from above only, so a camera high above a
// thin ground fog sees through it, and one far below a thick one none.
real march_fog_depth(real3 ro, real3 rd, real t) {
    real depth = FOG_DENSITY * t;
#ifdef ENABLE_FOG_LIGHT
    real a0 = -FOG_FALLOFF * (ro.y - FOG_HEIGHT);
    real k = FOG_FALLOFF * rd.y;
    real kt = k * t;
    if (k == R(0.0)) {
        // Level (k t would be 0 times INFINITY on a miss).
        depth = FOG_DENSITY * exp(fmin(a0, R(80.0))) * t;
    } else if (fabs(kt) < R(1e-4)) {
        depth = FOG_DENSITY * exp(fmin(a0, R(80.0))) * t * (R(1.0) - R(0.5) * kt);
    } else {
        depth = FOG_DENSITY * (exp(fmin(a0, R(80.0))) - exp(fmin(a0 - kt, R(80.0)))) / k;
    }
#endif
    return depth;
}
#endif

#ifdef ENABLE_FOG_LIGHT
// The distance from ro along the unit rd at which the fog's optical depth
// reaches depth (march_fog_depth inverted, for a depth the ray reaches):
// with q = depth / FOG_DENSITY, exp(a0) - exp(a0 - k s) = k q, so
// s = -log1p(-k q exp(-a0)) / k upwards and (log(exp(a0) + |k| q) - a0) / |k|
// downwards, q exp(-a0) near level.
real march_fog_reach(real3 ro, real3 rd, real depth) {
    real a0 = -FOG_FALLOFF * (ro.y - FOG_HEIGHT);
    real k = FOG_FALLOFF * rd.y;
    real q = depth / FOG_DENSITY;
    real level = q * exp(fmin(-a0, R(80.0)));
    if (fabs(k * level) < R(1e-4)) {
        return level * (R(1.0) + R(0.5) * k * level);
    }
    if (k > R(0.0)) {
        return -log1p(-fmin(k * level, R(1.0) - R(1e-7))) / k;
    }
    return (log(exp(fmin(a0, R(80.0))) - k * q) - a0) / -k;
}

// The light the fog scatters towards the camera along ro + rd s, s from 0
// to far (INFINITY on a miss), once (single scattering): the integral of
// density x transmittance x each light's radiance x pi x the phase
// function. Substituting u = 1 - exp(-depth(s)) makes the weight of every
// stretch of the ray its u: FOG_SAMPLES points spread evenly in u over [0,
// 1 - exp(-depth(far))], shifted together by jitter in [0, 1) (a new one
// every pass), each lit by every light through a shadow ray. Henyey and
// Greenstein's phase function for FOG_ANISOTROPY g, times pi:
// (1 - g^2) / (4 (1 + g^2 - 2 g cos)^1.5). Adds the shadow rays'
// evaluations to *evals.
real3 march_fog_light(real3 ro, real3 rd, real far, real jitter, const MarchCamera* cam,
                      __global const real* params, __global const real* lights,
                      int light_count, uint* evals) {
    real scattered = -expm1(-march_fog_depth(ro, rd, far));
    if (!(scattered > R(0.0))) {
        return (real3)(R(0.0));
    }
    real share = scattered / (real)FOG_SAMPLES;
    real g = FOG_ANISOTROPY;
    real3 sum = (real3)(R(0.0));
    for (int k = 0; k < FOG_SAMPLES; ++k) {
        real u = fmin(share * ((real)k + jitter), R(0.999999));
        real s = fmin(march_fog_reach(ro, rd, -log1p(-u)), far);
        real3 x = ro + rd * s;
        for (int i = 0; i < light_count; ++i) {
            __global const real* l = lights + LIGHT_STRIDE * i;
            real3 to_light;
            real light_distance;
            real3 radiance = march_light(l, x, &to_light, &light_distance);
            real bend = R(1.0) + g * g - R(2.0) * g * dot(to_light, rd);
            radiance *= (R(1.0) - g * g) / (R(4.0) * bend * sqrt(bend)) * share;
#ifdef ENABLE_SHADOWS
            real eps = DETAIL * march_footprint(cam, s);
            radiance *= march_shadow(x, to_light, light_distance, R(0.25) * eps, eps,
                                     l[LIGHT_SOFTNESS], fmax(radiance.x, fmax(radiance.y, radiance.z)),
                                     params, evals);
#endif
            sum += radiance;
        }
    }
    return sum;
}
#endif

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
#ifdef ENABLE_MATERIALS
    real16 material;
    DE_material(p, params, &material);
    *evals += 1u;
    specular_strength = material.MATERIAL_SPECULAR;
    shininess = material.MATERIAL_SHININESS;
    real through = R(0.0);
    if (material.MATERIAL_SUBSURFACE > R(0.0) && material.MATERIAL_SCATTER_DEPTH > R(0.0)) {
        through = material.MATERIAL_SUBSURFACE * march_thinness(p, n, material.MATERIAL_SCATTER_DEPTH, params, evals);
    }
#endif

    real3 sky = mix(SKY_BOTTOM, SKY_TOP, R(0.5) + R(0.5) * n.y);
#ifdef ENABLE_ENVIRONMENT
    sky = march_environment_irradiance(environment, n);
#endif
    real3 color = albedo * sky * (MARCH_AMBIENT * occlusion);
#ifdef ENABLE_MATERIALS
    *emitted = albedo * material.MATERIAL_EMISSION;
#endif

#ifdef ENABLE_SHADOWS
    // Shadow rays start one hit threshold off the surface and are blocked
    // within a quarter of it, so a surface does not shadow itself.
    real3 lifted = p + n * eps;
#endif
    for (int i = 0; i < light_count; ++i) {
        __global const real* l = lights + LIGHT_STRIDE * i;
        real3 to_light;
        real light_distance;
        real3 radiance = march_light(l, p, &to_light, &light_distance);
        real ndl = dot(n, to_light);
#ifdef ENABLE_MATERIALS
        if (ndl < R(0.0)) {
            color += radiance * albedo * (through * -ndl);
        }
#endif
        if (ndl <= R(0.0)) {
            continue;
        }
        real diffuse = R(1.0);
#ifdef ENABLE_MATERIALS
        diffuse = march_oren_nayar(material.MATERIAL_ROUGHNESS, n, to_light, -rd, ndl);
#endif
#ifdef ENABLE_SHADOWS
        // The most this light adds to the pixel in any channel.
        real3 most = radiance * ((albedo * diffuse + specular_strength) * ndl);
        real visible = march_shadow(lifted, to_light, light_distance, R(0.25) * eps, eps,
                                    l[LIGHT_SOFTNESS], fmax(most.x, fmax(most.y, most.z)),
                                    params, evals);
        if (visible <= R(0.0)) {
            continue;
        }
        radiance *= visible;
#endif
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
#ifdef ENABLE_SHADOWS
        visible = march_shadow(p + n * eps, to_light, light_distance, R(0.25) * eps, eps,
                               l[LIGHT_SOFTNESS], R(1.0), params, &evals);
#endif
        lit += weight * visible;
        weights += weight;
    }
    *shadow = weights > R(0.0) ? lit / weights : R(1.0);
}
