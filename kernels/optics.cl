// optics.cl — reflections and transparency, and where each sample looks.
//
// Follows shade.cl: the branching paths of reflective and transparent
// materials (ENABLE_MATERIALS), the per-sample jitter, the pixel and lens
// points of supersampling and depth of field, and the camera ray of a
// sample.

#ifdef ENABLE_MATERIALS
// A branch carrying less than this share of a pixel cannot change its
// 8-bit value: it is not traced.
#define MARCH_FAINT R(0.001953125) // 2^-9

// A reflected or refracted ray still to trace.
typedef struct {
    real3 ro;
    real3 rd;
    real3 weight;    // the share of the pixel's colour it brings
    real travelled;  // the path's length before ro: sets the footprint
    int depth;       // bounces so far, this one included
    int inside;      // whether it travels inside a transparent shape
} MarchBranch;

// The share of light a clear surface reflects, arriving from index 1 at
// an angle with cosine cos_i onto index ior: Fresnel's equations for
// unpolarised light (0 for ior 1, 1 on total internal reflection).
real march_fresnel(real cos_i, real ior) {
    real sin_t2 = (R(1.0) - cos_i * cos_i) / (ior * ior);
    if (sin_t2 >= R(1.0)) {
        return R(1.0);
    }
    real cos_t = sqrt(R(1.0) - sin_t2);
    real rs = (cos_i - ior * cos_t) / (cos_i + ior * cos_t);
    real rp = (cos_t - ior * cos_i) / (cos_t + ior * cos_i);
    return R(0.5) * (rs * rs + rp * rp);
}

// rd refracted through a surface with unit normal n facing it, going from
// index 1 to index 1 / eta; 0 on total internal reflection.
real3 march_refract(real3 rd, real3 n, real eta) {
    real cos_i = -dot(n, rd);
    real k = R(1.0) - eta * eta * (R(1.0) - cos_i * cos_i);
    return k < R(0.0) ? (real3)(R(0.0)) : eta * rd + (eta * cos_i - sqrt(k)) * n;
}

// Adds a branch of `weight` to the stack, or, a bounce too deep, returns
// the sky's share it brings instead (the cut-off). Branches too faint to
// show are dropped.
real3 march_branch(MarchBranch b, MarchBranch* stack, int* top,
                   __global const float* environment) {
    if (fmax(b.weight.x, fmax(b.weight.y, b.weight.z)) < MARCH_FAINT) {
        return (real3)(R(0.0));
    }
    if (b.depth > BOUNCES || *top >= BOUNCES + 2) {
        return b.weight * march_sky(b.rd, environment);
    }
    stack[(*top)++] = b;
    return (real3)(R(0.0));
}

// Splits the path that reaches surface point p (outward normal n, eps its
// hit threshold) along rd, t from the camera, carrying weight, after depth
// bounces: the material's reflectivity r and transparency tau, with the
// Fresnel reflectance F for index ior (march_fresnel), share it among
//   the surface's own colour, own: (1 - r)(1 - tau),
//   a reflected ray: r + (1 - r) tau F,
//   a refracted ray: (1 - r) tau (1 - F) (reflected too, on total
//   internal reflection);
// and the light the surface gives off, emitted, whole.
// Returns the colour it adds now; the rays go on the stack.
real3 march_split(real3 p, real3 n, real3 rd, real eps, real t, real3 weight, int depth,
                  real3 own, real3 emitted, __global const real* params, MarchBranch* stack,
                  int* top, __global const float* environment, uint* evals) {
    real16 material;
    DE_material(p, params, &material);
    *evals += 1u;
    real r = material.MATERIAL_REFLECTIVITY;
    real tau = material.MATERIAL_TRANSPARENCY;
    real ior = material.MATERIAL_IOR;
    real3 color = weight * (((R(1.0) - r) * (R(1.0) - tau)) * own + emitted);
    real reflected = r;
    if (tau > R(0.0)) {
        real fresnel = march_fresnel(clamp(-dot(n, rd), R(0.0), R(1.0)), ior);
        real3 bent = march_refract(rd, n, R(1.0) / ior);
        real passed = (R(1.0) - r) * tau * (R(1.0) - fresnel);
        if (dot(bent, bent) > R(0.0)) {
            MarchBranch b = {p - n * (R(2.0) * eps), normalize(bent), weight * passed, t,
                             depth + 1, 1};
            color += march_branch(b, stack, top, environment);
        } else {
            reflected += passed;
        }
        reflected += (R(1.0) - r) * tau * fresnel;
    }
    if (reflected > R(0.0)) {
        MarchBranch b = {p + n * (R(2.0) * eps), rd - R(2.0) * dot(rd, n) * n,
                         weight * reflected, t, depth + 1, 0};
        color += march_branch(b, stack, top, environment);
    }
    return color;
}

// The colour of a pixel's path that first meets the surface at p (normal
// n, hit threshold eps) t along rd, whose own lit colour is own and whose
// emission is emitted: own weighted by the surface's share, emitted
// whole, plus what its reflected and refracted
// rays bring, each marched like a primary ray (its footprint grows with
// the whole path's length) and lit with the same occlusion and shadows,
// depth first, at most BOUNCES deep. A ray inside a transparent shape
// marches to where it leaves (side -1) and refracts out, or reflects back
// in on total internal reflection; the inside is clear. Adds every
// evaluation to *evals.
real3 march_paths(real3 p, real3 n, real3 rd, real eps, real t, const MarchCamera* cam,
                  real3 own, real3 emitted, __global const real* params,
                  __global const real* lights, int light_count,
                  __global const float* environment, uint* evals) {
    MarchBranch stack[BOUNCES + 2];
    int top = 0;
    real3 color = march_split(p, n, rd, eps, t, (real3)(R(1.0)), 0, own, emitted, params,
                              stack, &top, environment, evals);
    while (top > 0) {
        MarchBranch b = stack[--top];
        // The footprint goes on growing along the path.
        MarchCamera along = *cam;
        along.footprint_base = march_footprint(cam, b.travelled);
        MarchResult m = march_ray(b.ro, b.rd, R(0.0), &along, b.inside ? R(-1.0) : R(1.0),
                                  params);
        *evals += (uint)m.steps;
        if (!m.hit) {
            color += b.weight * march_sky(b.rd, environment);
            continue;
        }
        real3 q = b.ro + b.rd * m.t;
        real footprint = march_footprint(&along, m.t);
        real3 nq = march_normal(q, NORMAL_EPSILON * footprint, b.rd, params);
        *evals += MARCH_NORMAL_EVALUATIONS;
        real eq = DETAIL * footprint;
        real travelled = b.travelled + m.t;
        if (b.inside) {
            real16 material;
            DE_material(q, params, &material);
            *evals += 1u;
            real3 out = march_refract(b.rd, -nq, material.MATERIAL_IOR);
            MarchBranch next = {q + nq * (R(2.0) * eq), normalize(out), b.weight, travelled,
                                b.depth + 1, 0};
            if (dot(out, out) <= R(0.0)) {
                next.ro = q - nq * (R(2.0) * eq);
                next.rd = b.rd - R(2.0) * dot(b.rd, nq) * nq;
                next.inside = 1;
            }
            color += march_branch(next, stack, &top, environment);
            continue;
        }
        real occlusion = march_occlusion(q, nq, footprint * cam->image_h, R(0.5), params, evals);
        real3 emitted;
        real3 lit = march_shade(q, nq, b.rd, eq, occlusion, params, lights, light_count,
                                environment, &emitted, evals);
        color += march_split(q, nq, b.rd, eq, travelled, b.weight, b.depth, lit, emitted,
                             params, stack, &top, environment, evals);
    }
    return color;
}
#endif

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
