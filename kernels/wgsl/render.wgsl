// The render kernel of kernels/*.cl in WGSL: where each sample looks
// (optics.cl: the pixel's and the lens's points, the camera ray), the
// normal, ambient occlusion, soft shadows, the orbit-trap tint, the
// lights, fog and glow (shade.cl), and the compute entry point `render`
// that marches, shades and writes each pixel (render.cl's render_tile).
// The formulas and constants are OpenCL's, line for line; where this file
// leaves out something that changes the picture, the backend refuses the
// scene or the option rather than draw something else
// (src/render/wgpu_backend.rs).
//
// Follows march.wgsl. The module defines before it, besides the march's
// constants: REAL_TINY, NORMAL_EPSILON, SUPERSAMPLING, GAMMA,
// EXPOSURE_SCALE, SKY_TOP, SKY_BOTTOM; ENABLE_AO with AO_SAMPLES and
// AO_DISTANCE, ENABLE_SHADOWS with SHADOW_STEPS, ENABLE_FOG with
// FOG_DENSITY, ENABLE_ENVIRONMENT (the `environment` buffer holds an
// image), ENABLE_FOG_LIGHT with FOG_FALLOFF, FOG_HEIGHT (in the
// module's frame), FOG_SAMPLES and FOG_ANISOTROPY, ENABLE_MATERIALS with
// BOUNCES, DEFAULT_MATERIAL and each value's lane MATERIAL_<value>,
// ENABLE_GI with march_path (paths.wgsl, or a stub without global
// illumination), ENABLE_BRUTE with march_stored, march_brute_phase,
// march_screen_normal and march_screen_occlusion (brute.wgsl, or stubs
// without inside shapes), ENABLE_CONE with cone_start (cone.wgsl, or a
// stub without the coarse pass) (a constant that is false leaves its code
// unreachable); the buffer layouts CAMERA_<field>, LIGHT_<field> and LIGHT_STRIDE
// (src/codegen/interface.rs, the tables the OpenCL kernel reads too);
// display_color (the display transform, printed from
// quality::display_formula); DE_shade and DE_material, and glow_color
// where GLOW_NODES is above 0.

// Shading constants that are not quality knobs (march.cl's).
const MARCH_AMBIENT: real = 0.5;      // strength of the sky's hemisphere light
const MARCH_SPECULAR: real = 0.25;    // Blinn-Phong specular strength
const MARCH_SHININESS: real = 32.0;   // Blinn-Phong exponent
const MARCH_NORMAL_EVALUATIONS: uint = 4u; // DE calls of march_normal
const AO_FALLOFF: real = 1.5;
const AO_FLOOR: real = 0.015625; // 2^-6
const AO_VIEW_FRACTION: real = 0.2;
const MARCH_PI: real = 3.14159265358979324;

// The camera (the `camera` buffer, laid out as CAMERA_<field>).
@group(0) @binding(1) var<storage, read> camera: array<real>;
// The lights, LIGHT_STRIDE reals each.
@group(0) @binding(2) var<storage, read> lights: array<real>;

// What changes from one frame to the next without rebuilding anything.
struct Frame {
    width: uint,       // the rendered image's size in pixels
    height: uint,
    light_count: uint,
    write_aovs: uint,  // 1: write aovs
    pass_index: int,   // the progressive pass; -1 for a frame of its own
}
@group(0) @binding(3) var<uniform> frame: Frame;
// The image, in the display's 8-bit steps.
@group(0) @binding(4) var image: texture_storage_2d<rgba8unorm, write>;
// The environment light (codegen::interface::environment's layout): its
// header, the image's texels and its irradiance map; the header alone,
// zeros, without one.
@group(0) @binding(6) var<storage, read> environment: array<f32>;
// Per pixel, the sum of every progressive pass's linear colours so far,
// and in w the samples that hit.
@group(0) @binding(7) var<storage, read_write> accumulation: array<real4>;
// Per pixel, for the ray through its centre: the distance to the hit (-1
// on a miss), 1 where it hit, the distance evaluations of the pixel's
// colour, and the primary march's.
@group(0) @binding(5) var<storage, read_write> aovs: array<real4>;
// With inside shapes, what the brute-force pass leaves for each sample s
// of the pass at (s * height + y) * width + x: its depth (on a miss, -1
// less the angle of its nearest miss) and its evaluations.
@group(0) @binding(8) var<storage, read_write> brute_depths: array<real2>;
// With the coarse pass, where each tile's rays start (cone.wgsl).
@group(0) @binding(9) var<storage, read_write> cone_starts: array<real>;

struct MarchCamera {
    origin: real3,
    right: real3,
    up: real3,
    forward: real3,
    half_w: real,
    half_h: real,
    footprint: real2, // a pixel's footprint at the eye, and its growth per unit along a ray
    image_w: real,
    image_h: real,
    pixel_scale: real,
    shift: real2,
    aperture: real,
    focus: real,
    orthographic: bool,
}

fn camera_vector(at: uint) -> real3 {
    return real3(camera[at], camera[at + 1u], camera[at + 2u]);
}

fn march_load_camera() -> MarchCamera {
    var cam: MarchCamera;
    cam.origin = camera_vector(CAMERA_ORIGIN);
    cam.orthographic = camera[CAMERA_ORTHOGRAPHIC] > 0.5;
    cam.right = camera_vector(CAMERA_RIGHT);
    cam.half_w = camera[CAMERA_HALF_WIDTH];
    cam.up = camera_vector(CAMERA_UP);
    cam.half_h = camera[CAMERA_HALF_HEIGHT];
    cam.forward = camera_vector(CAMERA_FORWARD);
    cam.footprint = real2(camera[CAMERA_FOOTPRINT_BASE], camera[CAMERA_FOOTPRINT_PER_UNIT]);
    cam.image_w = camera[CAMERA_IMAGE_WIDTH];
    cam.image_h = camera[CAMERA_IMAGE_HEIGHT];
    cam.pixel_scale = camera[CAMERA_PIXEL_SCALE];
    cam.shift = real2(camera[CAMERA_SHIFT], camera[CAMERA_SHIFT + 1u]);
    cam.aperture = camera[CAMERA_APERTURE];
    cam.focus = camera[CAMERA_FOCUS_DISTANCE];
    return cam;
}

// A ray: where it starts and its unit direction.
struct Ray {
    ro: real3,
    rd: real3,
}

// The ray through image position (px, py) in image pixels, (0, 0) being
// the top left corner of the image, through the centre of the lens.
fn march_camera_ray(cam: MarchCamera, px: real, py: real) -> Ray {
    let u = (2.0 * px / cam.image_w - 1.0) * cam.half_w + cam.shift.x * cam.half_h;
    let v = (1.0 - 2.0 * py / cam.image_h + cam.shift.y) * cam.half_h;
    if (cam.orthographic) {
        return Ray(cam.origin + cam.right * u + cam.up * v, cam.forward);
    }
    return Ray(cam.origin, normalize(cam.forward + cam.right * u + cam.up * v));
}

// The ray through image position (px, py) that leaves the lens at `lens`
// (the unit disc scaled to the aperture) and meets the centre's ray on the
// plane in focus.
fn march_lens_ray(cam: MarchCamera, px: real, py: real, lens: real2) -> Ray {
    var ray = march_camera_ray(cam, px, py);
    if (cam.aperture > 0.0) {
        let focus = ray.ro + ray.rd * (cam.focus / dot(ray.rd, cam.forward));
        ray.ro += (cam.right * lens.x + cam.up * lens.y) * cam.aperture;
        ray.rd = normalize(focus - ray.ro);
    }
    return ray;
}

// Deterministic per-sample jitter in [0, 1): the same image every run, and
// the same as the OpenCL kernel's.
fn march_hash(x_in: uint) -> uint {
    var x = x_in;
    x ^= x >> 16u;
    x *= 0x7feb352du;
    x ^= x >> 15u;
    x *= 0x846ca68bu;
    x ^= x >> 16u;
    return x;
}

fn march_jitter(x: uint, y: uint, sample: uint) -> real {
    let h = march_hash(x ^ march_hash(y ^ march_hash(sample)));
    return real(h >> 8u) * 5.9604644775390625e-8; // 2^-24
}

// Point j of the R2 sequence, rotated by a per-pixel offset (optics.cl).
fn march_pixel_point(pixel: uint, j: uint) -> real2 {
    let steps = (vec2<uint>(0xc13fa9a9u, 0x91e10da6u) * j) >> vec2<uint>(8u);
    let q = real2(march_jitter(pixel, 0u, 0u), march_jitter(pixel, 0u, 1u))
            + real2(real(steps.x), real(steps.y)) * 5.9604644775390625e-8; // 2^-24
    return q - floor(q);
}

// The radical inverse of j in base b.
fn march_radical_inverse(j_in: uint, b: uint) -> real {
    let step = 1.0 / real(b);
    var scale = step;
    var r = 0.0;
    for (var j = j_in; j > 0u; j /= b) {
        r += scale * real(j % b);
        scale *= step;
    }
    return r;
}

// Point j of the Halton sequence in bases 2 and 3, rotated by a per-pixel
// offset: where sample j leaves the lens, in the unit square.
fn march_lens_point(pixel: uint, j: uint) -> real2 {
    let q = real2(march_jitter(pixel, 0u, 2u), march_jitter(pixel, 0u, 3u))
            + real2(march_radical_inverse(j, 2u), march_radical_inverse(j, 3u));
    return q - floor(q);
}

// The unit square onto the unit disc (Shirley and Chiu's concentric map).
fn march_disc(q: real2) -> real2 {
    let a = 2.0 * q.x - 1.0;
    let b = 2.0 * q.y - 1.0;
    if (a == 0.0 && b == 0.0) {
        return real2(0.0);
    }
    let quarter = 0.78539816339744831;
    if (abs(a) > abs(b)) {
        return a * real2(cos(quarter * b / a), sin(quarter * b / a));
    }
    return b * real2(sin(quarter * a / b), cos(quarter * a / b));
}

// Where sample j (the s-th of its pass) lies in its pixel, in [0, 1)^2:
// jittered in cell s of an N x N grid with supersampling; without, the
// pixel's centre for sample 0 and the R2 sequence after it.
fn march_sample_point(pixel: uint, j: uint, s: int) -> real2 {
    if (SUPERSAMPLING > 1) {
        return real2((real(s % SUPERSAMPLING) + march_jitter(pixel, j, 0u)) / real(SUPERSAMPLING),
                     (real(s / SUPERSAMPLING) + march_jitter(pixel, j, 1u)) / real(SUPERSAMPLING));
    }
    if (j == 0u) {
        return real2(0.5);
    }
    return march_pixel_point(pixel, j);
}

// The ray of sample j (the s-th of its pass) of rendered pixel (x, y),
// whose index is pixel, and its image row.
struct SampleRay {
    ray: Ray,
    py: real,
}

fn march_sample_ray(cam: MarchCamera, x: int, y: int, pixel: uint, j: uint, s: int) -> SampleRay {
    let point = march_sample_point(pixel, j, s);
    var lens = real2(0.0);
    if (cam.aperture > 0.0) {
        lens = march_disc(march_lens_point(pixel, j));
    }
    let px = (real(x) + point.x) * cam.pixel_scale;
    let py = (real(y) + point.y) * cam.pixel_scale;
    return SampleRay(march_lens_ray(cam, px, py, lens), py);
}

// Unit normal by tetrahedral differences with step h; -rd where the
// gradient is flat.
fn march_normal(p: real3, h: real, rd: real3) -> real3 {
    let k = real2(1.0, -1.0);
    let g = k.xyy * DE(p + k.xyy * h) + k.yyx * DE(p + k.yyx * h)
            + k.yxy * DE(p + k.yxy * h) + k.xxx * DE(p + k.xxx * h);
    let len = length(g);
    if (len > REAL_TINY) {
        return g / len;
    }
    return -rd;
}

// The normal of a surface reached from outside, turned to face the ray.
fn march_facing(n: real3, rd: real3) -> real3 {
    let away = dot(n, rd);
    if (away > 0.0) {
        return normalize(n - 2.0 * away * rd);
    }
    return n;
}

// A material: its values in the lanes MATERIAL_<value> of a 4 x 4 matrix
// (WGSL has no 16-vector), the lanes after them zero.
alias real16 = mat4x4<f32>;

// Lane i of a material.
fn material_value(m: real16, i: int) -> real {
    return m[i / 4][i % 4];
}

// The material a fraction t of the way from a to b, lane by lane, as
// OpenCL's mix computes it.
fn material_mix(a: real16, b: real16, t: real) -> real16 {
    return a + (b - a) * t;
}

// t where c holds, else f (WGSL's select takes no matrices).
fn material_select(f: real16, t: real16, c: bool) -> real16 {
    if (c) {
        return t;
    }
    return f;
}

// Texel (x, y) of the w x h image at `at` in the environment's buffer.
fn march_env_texel(at: int, w: int, x: int, y: int) -> real3 {
    let i = at + 3 * (y * w + x);
    return real3(environment[i], environment[i + 1], environment[i + 2]);
}

// The w x h image at `at` at (u, v), bilinear between texel centres,
// wrapping across u and clamped in v (shade.cl's march_env_bilinear).
fn march_env_bilinear(at: int, w: int, h: int, uv: real2) -> real3 {
    let fx = uv.x * real(w) - 0.5;
    let fy = clamp(uv.y * real(h) - 0.5, 0.0, real(h - 1));
    let x0 = floor(fx);
    let y0 = floor(fy);
    let tx = fx - x0;
    let ty = fy - y0;
    var xa = int(x0) % w;
    if (xa < 0) {
        xa += w;
    }
    let xb = (xa + 1) % w;
    let ya = int(y0);
    let yb = min(ya + 1, h - 1);
    let a = march_env_texel(at, w, xa, ya);
    let b = march_env_texel(at, w, xb, ya);
    let c = march_env_texel(at, w, xa, yb);
    let e = march_env_texel(at, w, xb, yb);
    return mix(mix(a, b, tx), mix(c, e, tx), ty);
}

// The image coordinates of the unit direction d, in the image's frame
// turned about +Y (shade.cl's march_env_uv).
fn march_env_uv(d: real3) -> real2 {
    let c = environment[ENV_ROTATION_COS];
    let s = environment[ENV_ROTATION_SIN];
    let turned = real3(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
    return real2(0.5 + atan2(turned.x, -turned.z) / (2.0 * MARCH_PI),
                 acos(clamp(turned.y, -1.0, 1.0)) / MARCH_PI);
}

// The environment's radiance along the unit direction d, bilinear between
// texel centres: what the camera, mirrors and glass show.
fn march_environment(d: real3) -> real3 {
    let w = int(environment[ENV_WIDTH]);
    let h = int(environment[ENV_HEIGHT]);
    return march_env_bilinear(int(ENV_TEXELS), w, h, march_env_uv(d))
           * environment[ENV_INTENSITY];
}

// The environment's irradiance on a face turned along the unit normal n,
// over pi (precomputed by the host at a few texels).
fn march_environment_irradiance(n: real3) -> real3 {
    let w = int(environment[ENV_WIDTH]);
    let h = int(environment[ENV_HEIGHT]);
    let at = int(ENV_TEXELS) + 3 * w * h + (h + 1) + h * (w + 1);
    return march_env_bilinear(at, int(environment[ENV_IRRADIANCE_WIDTH]),
                              int(environment[ENV_IRRADIANCE_HEIGHT]), march_env_uv(n))
           * environment[ENV_INTENSITY];
}

// The sky seen along rd, where a reflected or refracted ray leaves the
// scene or is cut off: the environment light, or without one SKY_BOTTOM
// straight down and SKY_TOP straight up.
fn march_sky(rd: real3) -> real3 {
    if (ENABLE_ENVIRONMENT) {
        return march_environment(rd);
    }
    return mix(SKY_BOTTOM, SKY_TOP, clamp(0.5 + 0.5 * rd.y, 0.0, 1.0));
}

// Oren-Nayar's diffuse light for microfacet slopes spread by sigma,
// relative to Lambert's (shade.cl's march_oren_nayar).
fn march_oren_nayar(sigma: real, n: real3, l: real3, v: real3, ndl: real) -> real {
    if (sigma <= 0.0) {
        return 1.0;
    }
    let s2 = sigma * sigma;
    let a = 1.0 - 0.5 * s2 / (s2 + 0.33);
    let b = 0.45 * s2 / (s2 + 0.09);
    // The view can sit just behind a normal taken by differences.
    let ndv = clamp(dot(n, v), 1e-4, 1.0);
    let lt = l - n * ndl;
    let vt = v - n * ndv;
    let norms = length(lt) * length(vt);
    var cos_phi = 0.0;
    if (norms > REAL_TINY) {
        cos_phi = max(dot(lt, vt) / norms, 0.0);
    }
    let cos_alpha = min(ndl, ndv);
    let cos_beta = max(ndl, ndv);
    let sin_alpha = sqrt(max(1.0 - cos_alpha * cos_alpha, 0.0));
    let tan_beta = sqrt(max(1.0 - cos_beta * cos_beta, 0.0)) / cos_beta;
    return a + b * cos_phi * sin_alpha * tan_beta;
}

const MARCH_SCATTER_SAMPLES: int = 4; // DE calls of march_thinness

// How thin the shape is below p, with outward normal n, down to depth: 0
// where it is solid that deep, towards 1 where it ends sooner
// (shade.cl's march_thinness).
fn march_thinness(p: real3, n: real3, depth: real, evals: ptr<function, uint>) -> real {
    var solid = 0.0;
    for (var i = 1; i <= MARCH_SCATTER_SAMPLES; i++) {
        let h = depth * real(i) / real(MARCH_SCATTER_SAMPLES);
        solid += clamp(-DE(p - n * h) / h, 0.0, 1.0);
    }
    *evals += uint(MARCH_SCATTER_SAMPLES);
    return 1.0 - solid / real(MARCH_SCATTER_SAMPLES);
}

// Ambient occlusion along the normal out to a reach that is AO_DISTANCE or
// AO_VIEW_FRACTION of the view's height at p, whichever is shorter
// (shade.cl's march_ambient_occlusion); 1 without it. Adds its
// evaluations to *evals.
fn march_occlusion(p: real3, n: real3, view_height: real, offset: real,
                   evals: ptr<function, uint>) -> real {
    if (!ENABLE_AO) {
        return 1.0;
    }
    let reach = max(min(AO_DISTANCE, AO_VIEW_FRACTION * view_height), REAL_TINY);
    var missing = 0.0;
    var expected = 0.0;
    for (var i = 0; i < AO_SAMPLES; i++) {
        let h = reach * (real(i) + offset) / real(AO_SAMPLES);
        let weight = exp(-AO_FALLOFF * h / reach);
        let d = DE(p + n * h);
        missing += weight * clamp(h - d, 0.0, h);
        expected += weight * h;
    }
    *evals += uint(AO_SAMPLES);
    return clamp(1.0 - missing / expected, AO_FLOOR, 1.0);
}

// Visibility of a light from ro along rd, from start to max_t: 0 in full
// shadow, 1 fully lit; Quilez's improved soft shadow for softness above 0,
// stopping where the rest cannot change the pixel (shade.cl's
// march_shadow). Adds its evaluations to *evals.
fn march_shadow(ro: real3, rd: real3, max_t_in: real, eps: real, start: real, softness: real,
                weight: real, evals: ptr<function, uint>) -> real {
    var visible = 1.0;
    var prev_h = 1e20;
    var prev_step = 0.0; // from the previous sample to this one
    var t = start;
    var max_t = max_t_in;
    let faint = sqrt(0.5 / (255.0 * 3.0 * max(weight, REAL_TINY)));
    if (SCENE_BOUNDED) {
        let oc = ro - SCENE_BOUND_CENTRE;
        let b = dot(oc, rd);
        let widened = SCENE_BOUND_RADIUS + eps / SCENE_BOUND_SLOPE;
        let disc = b * b - (dot(oc, oc) - widened * widened);
        var t_exit = -1.0;
        if (disc >= 0.0) {
            t_exit = -b + sqrt(disc);
        }
        if (softness <= 0.0) {
            max_t = min(max_t, t_exit);
        }
    }
    // Inside shapes block the ray where a sample lands in them: samples
    // BRUTE_STEP times 4 of the shaded pixel's footprints apart (start is
    // DETAIL footprints), beyond SHADOW_STEPS, from two samples out (the
    // dust next to a hit would shadow every point of it).
    let lattice = 4.0 * BRUTE_STEP * start / DETAIL;
    var span = real2(1.0, -1.0);
    if (ENABLE_BRUTE) {
        span = march_brute_span(ro, rd);
        span.x = max(span.x, 2.0 * lattice);
    }
    var next_sample = -1.0;
    var brute_steps = 0;
    for (var i = 0; i < SHADOW_STEPS && t < max_t; i++) {
        var h = DE(ro + rd * t);
        *evals += 1u;
        if (ENABLE_BRUTE && h <= -0.5 * INSIDE_HUGE && t < span.x) {
            // The dust next to the start: no information.
            h = INSIDE_HUGE;
        }
        if (h < eps) {
            return 0.0;
        }
        if (softness > 0.0) {
            // Where the two distance spheres cross, if between the two
            // samples (shade.cl's march_shadow says why).
            var y = 0.0;
            if (h < 2.0 * prev_h) {
                y = h * h / (2.0 * prev_h);
            }
            if (y >= prev_step) {
                y = 0.0;
            }
            let side = sqrt(max(h * h - y * y, 0.0));
            visible = min(visible, side / (softness * max(t - y, REAL_TINY)));
            prev_h = h;
            if (visible < faint) {
                return 0.0;
            }
        }
        var step = max(h, eps);
        if (ENABLE_BRUTE) {
            let brute = march_brute_step(t, step, span, lattice, 0.5, &next_sample);
            if (brute < step) {
                step = brute;
                if (brute_steps < BRUTE_MAX_STEPS) {
                    brute_steps += 1;
                    i -= 1;
                }
            }
        }
        t += step;
        prev_step = step;
    }
    visible = clamp(visible, 0.0, 1.0);
    return visible * visible * (3.0 - 2.0 * visible);
}

// Orbit-trap tint: a cosine palette that fades to white as the trap
// reaches 1.
fn march_trap_tint(trap: real) -> real3 {
    let t = clamp(trap, 0.0, 1.0);
    let phase = real3(0.0, 0.1, 0.2) + t;
    let palette = 0.5 + 0.5 * cos(2.0 * MARCH_PI * phase);
    return mix(palette, real3(1.0), t);
}

// Background at image row py: SKY_BOTTOM at the bottom, SKY_TOP at the top.
fn march_background(cam: MarchCamera, py: real) -> real3 {
    let v = clamp(1.0 - py / cam.image_h, 0.0, 1.0);
    return mix(SKY_BOTTOM, SKY_TOP, v);
}

// Light i as seen from p: the unit direction towards it, how far it is
// (MAX_DISTANCE for a directional light) and the radiance that arrives
// (shade.cl's march_light).
struct LightSample {
    to_light: real3,
    distance: real,
    radiance: real3,
}

fn light_vector(at: uint) -> real3 {
    return real3(lights[at], lights[at + 1u], lights[at + 2u]);
}

fn march_light(i: uint, p: real3) -> LightSample {
    let at = LIGHT_STRIDE * i;
    let v = light_vector(at + LIGHT_POSITION);
    var l = LightSample(v, MAX_DISTANCE, light_vector(at + LIGHT_RADIANCE));
    let kind = lights[at + LIGHT_KIND];
    if (kind > 0.5) {
        let delta = v - p;
        let dist2 = max(dot(delta, delta), REAL_TINY);
        l.distance = sqrt(dist2);
        l.to_light = delta / l.distance;
        l.radiance /= dist2;
        if (kind > 2.5) {
            // A rectangle lights its own side, dimming with the angle.
            let face = cross(normalize(light_vector(at + LIGHT_EDGE_U)),
                             normalize(light_vector(at + LIGHT_EDGE_V)));
            l.radiance *= max(dot(face, -l.to_light), 0.0);
        }
    }
    return l;
}

// A lit surface: its colour, and the light it gives off (which no share
// of reflection or transparency dims).
struct Lit {
    color: real3,
    emitted: real3,
}

// Lit colour of the surface point p with normal n, seen along rd, with the
// sky's light scaled by occlusion: per light, Lambert's or with a
// material's roughness Oren-Nayar's diffuse term plus a Blinn-Phong
// highlight, through its shadow ray; a material's subsurface light from
// behind, and its emission apart (shade.cl's march_shade). Adds its
// evaluations to *evals.
fn march_shade(p: real3, n: real3, rd: real3, eps: real, occlusion: real,
               evals: ptr<function, uint>) -> Lit {
    var out: Lit;
    out.emitted = real3(0.0);
    var albedo: real3;
    var trap: real2;
    DE_shade(p, &albedo, &trap);
    *evals += 1u;
    albedo *= march_trap_tint(trap.x);
    var specular_strength = MARCH_SPECULAR;
    var shininess = MARCH_SHININESS;
    var material = DEFAULT_MATERIAL;
    var through = 0.0;
    if (ENABLE_MATERIALS) {
        DE_material(p, &material);
        *evals += 1u;
        specular_strength = material_value(material, MATERIAL_SPECULAR);
        shininess = material_value(material, MATERIAL_SHININESS);
        let subsurface = material_value(material, MATERIAL_SUBSURFACE);
        let depth = material_value(material, MATERIAL_SCATTER_DEPTH);
        if (subsurface > 0.0 && depth > 0.0) {
            through = subsurface * march_thinness(p, n, depth, evals);
        }
        out.emitted = albedo * material_value(material, MATERIAL_EMISSION);
    }
    var sky = mix(SKY_BOTTOM, SKY_TOP, 0.5 + 0.5 * n.y);
    if (ENABLE_ENVIRONMENT) {
        sky = march_environment_irradiance(n);
    }
    var color = albedo * sky * (MARCH_AMBIENT * occlusion);
    // Shadow rays start one hit threshold off the surface and are blocked
    // within a quarter of it, so a surface does not shadow itself.
    let lifted = p + n * eps;
    for (var i = 0u; i < frame.light_count; i++) {
        let l = march_light(i, p);
        var radiance = l.radiance;
        let ndl = dot(n, l.to_light);
        if (ENABLE_MATERIALS && ndl < 0.0) {
            color += radiance * albedo * (through * -ndl);
        }
        if (ndl <= 0.0) {
            continue;
        }
        var diffuse = 1.0;
        if (ENABLE_MATERIALS) {
            diffuse = march_oren_nayar(material_value(material, MATERIAL_ROUGHNESS), n,
                                       l.to_light, -rd, ndl);
        }
        if (ENABLE_SHADOWS) {
            // The most this light adds to the pixel in any channel.
            let most = radiance * ((albedo * diffuse + specular_strength) * ndl);
            let visible = march_shadow(lifted, l.to_light, l.distance, 0.25 * eps, eps,
                                       lights[LIGHT_STRIDE * i + LIGHT_SOFTNESS],
                                       max(most.x, max(most.y, most.z)), evals);
            if (visible <= 0.0) {
                continue;
            }
            radiance *= visible;
        }
        let half_vector = normalize(l.to_light - rd);
        // OpenCL's pow(x, 0) is 1 for every x; Vulkan's, exp2(0 log2 x), is
        // not defined at x = 0.
        var highlight = 1.0;
        if (shininess != 0.0) {
            highlight = pow(max(dot(n, half_vector), 0.0), shininess);
        }
        let specular = specular_strength * highlight;
        color += radiance * (albedo * (diffuse * ndl) + specular * ndl);
    }
    out.color = color;
    return out;
}

// A branch carrying less than this share of a pixel cannot change its
// 8-bit value: it is not traced.
const MARCH_FAINT: real = 0.001953125; // 2^-9

// A reflected or refracted ray still to trace (optics.cl's MarchBranch).
struct MarchBranch {
    ro: real3,
    rd: real3,
    weight: real3,   // the share of the pixel's colour it brings
    travelled: real, // the path's length before ro: sets the footprint
    depth: int,      // bounces so far, this one included
    inside: bool,    // whether it travels inside a transparent shape
}

// The share of light a clear surface reflects (Fresnel's equations for
// unpolarised light; 1 on total internal reflection).
fn march_fresnel(cos_i: real, ior: real) -> real {
    let sin_t2 = (1.0 - cos_i * cos_i) / (ior * ior);
    if (sin_t2 >= 1.0) {
        return 1.0;
    }
    let cos_t = sqrt(1.0 - sin_t2);
    let rs = (cos_i - ior * cos_t) / (cos_i + ior * cos_t);
    let rp = (cos_t - ior * cos_i) / (cos_t + ior * cos_i);
    return 0.5 * (rs * rs + rp * rp);
}

// rd refracted through a surface with unit normal n facing it, going from
// index 1 to index 1 / eta; 0 on total internal reflection.
fn march_refract(rd: real3, n: real3, eta: real) -> real3 {
    let cos_i = -dot(n, rd);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if (k < 0.0) {
        return real3(0.0);
    }
    return eta * rd + (eta * cos_i - sqrt(k)) * n;
}

// The branches of one pixel's path still to trace, depth first.
struct Branches {
    stack: array<MarchBranch, BRANCH_SLOTS>,
    top: int,
}

// Adds a branch to the stack, or, a bounce too deep, returns the sky's
// share it brings instead; branches too faint to show are dropped
// (optics.cl's march_branch).
fn march_branch(b: MarchBranch, branches: ptr<function, Branches>) -> real3 {
    if (max(b.weight.x, max(b.weight.y, b.weight.z)) < MARCH_FAINT) {
        return real3(0.0);
    }
    if (b.depth > BOUNCES || (*branches).top >= BOUNCES + 2) {
        return b.weight * march_sky(b.rd);
    }
    (*branches).stack[(*branches).top] = b;
    (*branches).top += 1;
    return real3(0.0);
}

// Shares the path that reaches p (normal n, hit threshold eps) along rd,
// t from the camera, carrying weight, after depth bounces, among the
// surface's own colour, a reflected and a refracted ray (optics.cl's
// march_split). Returns the colour it adds now; the rays go on the stack.
fn march_split(p: real3, n: real3, rd: real3, eps: real, t: real, weight: real3, depth: int,
               own: real3, emitted: real3, branches: ptr<function, Branches>,
               evals: ptr<function, uint>) -> real3 {
    var material: real16;
    DE_material(p, &material);
    *evals += 1u;
    let r = material_value(material, MATERIAL_REFLECTIVITY);
    let tau = material_value(material, MATERIAL_TRANSPARENCY);
    let ior = material_value(material, MATERIAL_IOR);
    var color = weight * (((1.0 - r) * (1.0 - tau)) * own + emitted);
    var reflected = r;
    if (tau > 0.0) {
        let fresnel = march_fresnel(clamp(-dot(n, rd), 0.0, 1.0), ior);
        let bent = march_refract(rd, n, 1.0 / ior);
        let passed = (1.0 - r) * tau * (1.0 - fresnel);
        if (dot(bent, bent) > 0.0) {
            let b = MarchBranch(p - n * (2.0 * eps), normalize(bent), weight * passed, t,
                                depth + 1, true);
            color += march_branch(b, branches);
        } else {
            reflected += passed;
        }
        reflected += (1.0 - r) * tau * fresnel;
    }
    if (reflected > 0.0) {
        let b = MarchBranch(p + n * (2.0 * eps), rd - 2.0 * dot(rd, n) * n,
                            weight * reflected, t, depth + 1, false);
        color += march_branch(b, branches);
    }
    return color;
}

// The colour of a pixel's path that first meets the surface at p: own
// weighted by the surface's share, emitted whole, plus what its reflected
// and refracted rays bring, each marched like a primary ray and lit alike,
// depth first, at most BOUNCES deep (optics.cl's march_paths).
fn march_paths(p: real3, n: real3, rd: real3, eps: real, t: real, cam: MarchCamera,
               own: real3, emitted: real3, evals: ptr<function, uint>) -> real3 {
    var branches: Branches;
    branches.top = 0;
    var color = march_split(p, n, rd, eps, t, real3(1.0), 0, own, emitted, &branches, evals);
    while (branches.top > 0) {
        branches.top -= 1;
        let b = branches.stack[branches.top];
        // The footprint goes on growing along the path.
        let along = real2(march_footprint(cam.footprint, b.travelled), cam.footprint.y);
        let m = march_ray(b.ro, b.rd, 0.0, along, select(1.0, -1.0, b.inside));
        *evals += uint(m.steps);
        if (!m.hit) {
            color += b.weight * march_sky(b.rd);
            continue;
        }
        let q = b.ro + b.rd * m.t;
        let footprint = march_footprint(along, m.t);
        let nq = march_normal(q, NORMAL_EPSILON * footprint, b.rd);
        *evals += MARCH_NORMAL_EVALUATIONS;
        let eq = DETAIL * footprint;
        let travelled = b.travelled + m.t;
        if (b.inside) {
            var material: real16;
            DE_material(q, &material);
            *evals += 1u;
            let out = march_refract(b.rd, -nq, material_value(material, MATERIAL_IOR));
            var next = MarchBranch(q + nq * (2.0 * eq), normalize(out), b.weight, travelled,
                                   b.depth + 1, false);
            if (dot(out, out) <= 0.0) {
                next.ro = q - nq * (2.0 * eq);
                next.rd = b.rd - 2.0 * dot(b.rd, nq) * nq;
                next.inside = true;
            }
            color += march_branch(next, &branches);
            continue;
        }
        let occlusion = march_occlusion(q, nq, footprint * cam.image_h, 0.5, evals);
        let lit = march_shade(q, nq, b.rd, eq, occlusion, evals);
        color += march_split(q, nq, b.rd, eq, travelled, b.weight, b.depth, lit.color,
                             lit.emitted, &branches, evals);
    }
    return color;
}

// exp(x) - 1 and log(1 + x), without the cancellation near 0 (WGSL has
// neither built in).
fn fsdf_expm1(x: real) -> real {
    if (abs(x) < 1e-4) {
        return x * (1.0 + 0.5 * x);
    }
    return exp(x) - 1.0;
}

fn fsdf_log1p(x: real) -> real {
    if (abs(x) < 1e-4) {
        return x * (1.0 - 0.5 * x);
    }
    return log(1.0 + x);
}

// The fog's optical depth from ro along the unit rd out to t (which may be
// FSDF_INFINITY): FOG_DENSITY t for a uniform fog; for lit fog, whose
// density falls by FOG_FALLOFF with height above FOG_HEIGHT, the fall of
// the density along the ray over its rate (shade.cl's march_fog_depth).
fn march_fog_depth(ro: real3, rd: real3, t: real) -> real {
    if (!ENABLE_FOG_LIGHT) {
        return FOG_DENSITY * t;
    }
    let a0 = -FOG_FALLOFF * (ro.y - FOG_HEIGHT);
    let k = FOG_FALLOFF * rd.y;
    let kt = k * t;
    if (k == 0.0) {
        // Level (k t would be 0 times infinity on a miss).
        return FOG_DENSITY * exp(min(a0, 80.0)) * t;
    }
    if (abs(kt) < 1e-4) {
        return FOG_DENSITY * exp(min(a0, 80.0)) * t * (1.0 - 0.5 * kt);
    }
    return FOG_DENSITY * (exp(min(a0, 80.0)) - exp(min(a0 - kt, 80.0))) / k;
}

// The distance from ro along rd at which the fog's optical depth reaches
// depth (shade.cl's march_fog_reach).
fn march_fog_reach(ro: real3, rd: real3, depth: real) -> real {
    let a0 = -FOG_FALLOFF * (ro.y - FOG_HEIGHT);
    let k = FOG_FALLOFF * rd.y;
    let q = depth / FOG_DENSITY;
    let level = q * exp(min(-a0, 80.0));
    if (abs(k * level) < 1e-4) {
        return level * (1.0 + 0.5 * k * level);
    }
    if (k > 0.0) {
        return -fsdf_log1p(-min(k * level, 1.0 - 1e-7)) / k;
    }
    return (log(exp(min(a0, 80.0)) - k * q) - a0) / -k;
}

// The light the fog scatters towards the camera along ro + rd s, s from 0
// to far, once: FOG_SAMPLES points spread evenly in the fog's
// transmittance, shifted together by jitter, each lit by every light
// through a shadow ray, with Henyey and Greenstein's phase function
// (shade.cl's march_fog_light). Adds the shadow rays' evaluations to
// *evals.
fn march_fog_light(ro: real3, rd: real3, far: real, jitter: real, cam: MarchCamera,
                   evals: ptr<function, uint>) -> real3 {
    let scattered = -fsdf_expm1(-march_fog_depth(ro, rd, far));
    if (!(scattered > 0.0)) {
        return real3(0.0);
    }
    let share = scattered / real(FOG_SAMPLES);
    let g = FOG_ANISOTROPY;
    var sum = real3(0.0);
    for (var k = 0; k < FOG_SAMPLES; k++) {
        let u = min(share * (real(k) + jitter), 0.999999);
        let s = min(march_fog_reach(ro, rd, -fsdf_log1p(-u)), far);
        let x = ro + rd * s;
        for (var i = 0u; i < frame.light_count; i++) {
            let l = march_light(i, x);
            let bend = 1.0 + g * g - 2.0 * g * dot(l.to_light, rd);
            var radiance = l.radiance * ((1.0 - g * g) / (4.0 * bend * sqrt(bend)) * share);
            if (ENABLE_SHADOWS) {
                let eps = DETAIL * march_footprint(cam.footprint, s);
                radiance *= march_shadow(x, l.to_light, l.distance, 0.25 * eps, eps,
                                         lights[LIGHT_STRIDE * i + LIGHT_SOFTNESS],
                                         max(radiance.x, max(radiance.y, radiance.z)), evals);
            }
            sum += radiance;
        }
    }
    return sum;
}

// A pixel's samples of this pass and what they cost: the sum of their
// linear colours, how many hit, and for the first sample's ray, the
// march.
struct Shaded {
    sum: real3,
    hits: uint,
    evals: uint,
    steps: uint,
    centre: MarchResult,
}

const PER_PASS: int = SUPERSAMPLING * SUPERSAMPLING;

// Marches and shades the samples of rendered pixel (x, y) (render.cl's
// render_tile): progressive pass k >= 0 takes samples k N^2 to
// (k + 1) N^2 - 1, a frame of its own the first N^2.
fn shade_pixel(cam: MarchCamera, x: int, y: int, pixel: uint) -> Shaded {
    var out: Shaded;
    var sum = real3(0.0);
    var evals = 0u;
    var steps = 0u;
    var hits = 0u;
    let first = uint(max(frame.pass_index, 0) * PER_PASS);
    // Where the pixel's rays start: past the empty space the coarse pass
    // found in front of its tile.
    var start = 0.0;
    if (ENABLE_CONE) {
        start = cone_start(x, y);
    }
    for (var s = 0; s < PER_PASS; s++) {
        let j = first + uint(s);
        let sample = march_sample_ray(cam, x, y, pixel, j, s);
        let ro = sample.ray.ro;
        let rd = sample.ray.rd;
        var m: MarchResult;
        if (ENABLE_BRUTE) {
            // Marched by the brute-force pass.
            m = march_stored(x, y, s);
        } else {
            m = march_ray(ro, rd, start, cam.footprint, 1.0);
        }
        steps += uint(m.steps);
        evals += uint(m.steps);
        var background = march_background(cam, sample.py);
        if (ENABLE_ENVIRONMENT || ENABLE_GI) {
            // The sky that lights the paths, or the environment, seen
            // along the ray.
            background = march_sky(rd);
        }
        var color = background;
        if (m.hit) {
            hits += 1u;
            var p = ro + rd * m.t;
            let footprint = march_footprint(cam.footprint, m.t);
            var view_height = footprint * cam.image_h;
            // Whether p lies in an inside shape, which has no distance to
            // take a normal or occlusion from.
            var in_set = false;
            var n: real3;
            if (ENABLE_BRUTE) {
                in_set = DE(p) <= -0.5 * INSIDE_HUGE;
                evals += 1u;
                if (in_set) {
                    n = march_screen_normal(cam, x, y, s, j, p, rd, footprint);
                }
            }
            if (!in_set) {
                n = march_normal(p, NORMAL_EPSILON * footprint, rd);
                evals += MARCH_NORMAL_EVALUATIONS;
                if (m.t > 0.0) {
                    n = march_facing(n, rd);
                } else {
                    // The ray starts inside the surface: shade the nearest
                    // point of the surface instead, with no view to scale
                    // occlusion to.
                    p -= n * DE(p);
                    evals += 1u;
                    view_height = FSDF_INFINITY;
                }
            }
            if (ENABLE_GI) {
                color = march_path(p, n, rd, max(m.t, 0.0), cam, pixel, j, &evals);
            } else {
                // Occlusion samples at the midpoints of their intervals;
                // with inside shapes, which the samples see only where
                // they land in one, jittered like the march's steps, so
                // passes average the all-or-nothing samples.
                var offset = 0.5;
                if (ENABLE_BRUTE) {
                    offset = march_brute_phase(pixel, j);
                }
                var occlusion = march_occlusion(p, n, view_height, offset, &evals);
                if (ENABLE_BRUTE) {
                    // The neighbours' depths add what the screen shows
                    // around the hit.
                    occlusion *= march_screen_occlusion(cam, x, y, s, j, p, n, footprint,
                                                        view_height);
                }
                let lit = march_shade(p, n, rd, DETAIL * footprint, occlusion, &evals);
                color = lit.color;
                if (ENABLE_MATERIALS) {
                    color = march_paths(p, n, rd, DETAIL * footprint, m.t, cam, lit.color,
                                        lit.emitted, &evals);
                }
            }
            if (ENABLE_FOG) {
                // What the fog takes away, the sky puts back.
                color = mix(background, color, exp(-march_fog_depth(ro, rd, m.t)));
            }
        } else if (ENABLE_GLOW) {
            color += GLOW_COLOR * (GLOW_STRENGTH * exp(-MARCH_GLOW_FALLOFF * m.closest));
            for (var k = 0; k < GLOW_NODES; k++) {
                color += glow_color(k) * exp(-MARCH_GLOW_FALLOFF * m.glow_closest[k]);
            }
        }
        if (ENABLE_FOG_LIGHT) {
            var far = FSDF_INFINITY;
            if (m.hit) {
                far = max(m.t, 0.0);
            }
            color += march_fog_light(ro, rd, far, march_jitter(pixel, j, 4u), cam, &evals);
        }
        sum += color;
        if (s == 0) {
            out.centre = m;
        }
    }
    out.sum = sum;
    out.hits = hits;
    out.evals = evals;
    out.steps = steps;
    return out;
}

// One invocation per rendered pixel: its colour through the display
// transform into `image`, and with write_aovs its ray's depth, hit and
// costs into `aovs`.
@compute @workgroup_size(8, 8)
fn render(@builtin(global_invocation_id) id: vec3<uint>) {
    if (id.x >= frame.width || id.y >= frame.height) {
        return;
    }
    let cam = march_load_camera();
    let x = int(id.x);
    let y = int(id.y);
    let pixel = id.y * frame.width + id.x;
    let shaded = shade_pixel(cam, x, y, pixel);
    var color = shaded.sum / real(PER_PASS);
    let pass_index = frame.pass_index;
    if (pass_index >= 0) {
        // The spare fourth float sums the samples that hit.
        var total = real4(0.0);
        if (pass_index > 0) {
            total = accumulation[pixel];
        }
        total += real4(shaded.sum, real(shaded.hits));
        accumulation[pixel] = total;
        if (pass_index > 0) {
            color = total.xyz / (real(pass_index + 1) * real(PER_PASS));
        }
    }
    let display = display_color(color, EXPOSURE_SCALE, 1.0 / GAMMA);
    // Rounded to the display's 8-bit steps here, to the nearest as the
    // OpenCL kernel rounds, so the store needs no rounding of its own.
    let steps = round(clamp(display, real3(0.0), real3(1.0)) * 255.0) / 255.0;
    textureStore(image, vec2<int>(x, y), real4(steps, 1.0));
    // Later passes leave the outputs of the first: the same rays.
    if (frame.write_aovs != 0u && pass_index <= 0) {
        var centre = shaded.centre;
        if (!ENABLE_BRUTE && (SUPERSAMPLING > 1 || cam.aperture > 0.0)) {
            // The colour samples are jittered: trace the pixel centre.
            // Rays marched by brute force report their first sample's
            // instead: its normal needs the neighbours' samples.
            let ray = march_camera_ray(cam, (real(x) + 0.5) * cam.pixel_scale,
                                       (real(y) + 0.5) * cam.pixel_scale);
            var start = 0.0;
            if (ENABLE_CONE) {
                start = cone_start(x, y);
            }
            centre = march_ray(ray.ro, ray.rd, start, cam.footprint, 1.0);
        }
        var depth = -1.0;
        if (centre.hit) {
            depth = centre.t;
        }
        aovs[pixel] = real4(depth, select(0.0, 1.0, centre.hit), real(shaded.evals),
                            real(shaded.steps));
    }
}
