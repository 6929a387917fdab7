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

#ifdef ENABLE_GI
// Bounces after which Russian roulette may end a path.
#define GI_ROULETTE 3
// The least and most chance a path has of surviving the roulette.
#define GI_SURVIVE_MIN R(0.05)
#define GI_SURVIVE_MAX R(0.95)
#define GI_PI R(3.14159265358979324)

// Random number k of bounce `bounce` of sample j of a pixel, in [0, 1):
// independent of the numbers that place the sample in the pixel and on
// the lens.
real march_random(uint pixel, uint j, int bounce, uint k) {
    return march_jitter(pixel, j, 16u + 8u * (uint)bounce + k);
}

// The unit vector at polar angle acos(cos_theta) from the unit vector n,
// turned by 2 pi u about it (Duff et al.'s orthonormal basis, 2017).
real3 march_around(real3 n, real cos_theta, real u) {
    real s = n.z >= R(0.0) ? R(1.0) : R(-1.0);
    real a = R(-1.0) / (s + n.z);
    real c = n.x * n.y * a;
    real3 t = (real3)(R(1.0) + s * n.x * n.x * a, s * c, -s * n.x);
    real3 b = (real3)(c, s + n.y * n.y * a, -n.y);
    real sin_theta = sqrt(fmax(R(1.0) - cos_theta * cos_theta, R(0.0)));
    real phi = R(2.0) * GI_PI * u;
    return t * (sin_theta * cos(phi)) + b * (sin_theta * sin(phi)) + n * cos_theta;
}

// Whether nothing blocks the segment from ro along the unit rd up to
// max_t: the same march as the path's rays, with the footprint of a
// pixel travelled `travelled` from the camera.
int march_visible(real3 ro, real3 rd, real max_t, const MarchCamera* cam, real travelled,
                  __global const real* params, uint* evals) {
    MarchCamera along = *cam;
    along.footprint_base = march_footprint(cam, travelled);
    MarchResult m = march_ray(ro, rd, R(0.0), &along, R(1.0), params);
    *evals += (uint)m.steps;
    return !m.hit || m.t >= max_t;
}

// The surface's scattering, as a BRDF times pi: the diffuse share
// (1 - ks) albedo (Oren-Nayar's factor for roughness sigma) plus the
// specular share ks of a normalised Phong lobe of exponent s about the
// mirror direction of the view, (s + 2) / 2 cos^s(alpha). n.l is left to
// the caller.
real3 march_brdf(real3 n, real3 to_light, real3 rd, real3 albedo, real ks, real shininess,
                 real sigma, real ndl) {
    real3 diffuse = albedo * (R(1.0) - ks);
#ifdef ENABLE_MATERIALS
    diffuse *= march_oren_nayar(sigma, n, to_light, -rd, ndl);
#endif
    real3 mirror = rd - R(2.0) * dot(rd, n) * n;
    // Nothing behind the mirror direction (pow(0, 0) is 1: shininess 0).
    real c = dot(mirror, to_light);
    real lobe = c > R(0.0) ? pow(c, shininess) : R(0.0);
    return diffuse + ks * (shininess + R(2.0)) * R(0.5) * lobe;
}

// The density, over solid angle, with which the surface's scattering
// (march_path) sends a path leaving p (normal n, reached along rd) along
// the unit direction d: the diffuse share's cosine lobe and the specular
// share's Phong lobe.
real march_brdf_pdf(real3 n, real3 rd, real3 d, real ks, real shininess) {
    real ndl = dot(n, d);
    if (ndl <= R(0.0)) {
        return R(0.0);
    }
    real3 mirror = rd - R(2.0) * dot(rd, n) * n;
    real c = dot(mirror, d);
    real lobe = c > R(0.0) ? pow(c, shininess) : R(0.0);
    return ((R(1.0) - ks) * ndl + ks * (shininess + R(1.0)) * R(0.5) * lobe) / GI_PI;
}

// The weight of a sample drawn with density a, where another strategy
// would have drawn it with density b (Veach's power heuristic,
// a^2 / (a^2 + b^2), by the ratio of the smaller to the larger: densities
// near a pole of the environment overflow when squared).
real march_power_heuristic(real a, real b) {
    if (!(a > R(0.0))) {
        return R(0.0);
    }
    if (a >= b) {
        real r = b / a;
        return R(1.0) / (R(1.0) + r * r);
    }
    real r = a / b;
    return r * r / (R(1.0) + r * r);
}

#ifdef ENABLE_ENVIRONMENT
// The environment image's texel (x, y) of row y's conditional distribution
// and the marginal distribution of rows (codegen::interface::environment):
// cumulative sums, 0 first and 1 last, of each texel's luminance times the
// sine of its row's polar angle.
int march_env_marginal(int w, int h) {
    return ENV_TEXELS + 3 * w * h;
}

int march_env_conditional(int w, int h, int row) {
    return march_env_marginal(w, h) + (h + 1) + row * (w + 1);
}

// The bin of the n + 1 cumulative sums at `at` that holds u, and where in
// it u lies (in [0, 1)).
int march_env_find(__global const float* env, int at, int n, real u, real* frac) {
    int lo = 0;
    int hi = n;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if ((real)env[at + mid] <= u) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    real width = (real)env[at + lo + 1] - (real)env[at + lo];
    *frac = width > R(0.0) ? clamp((u - (real)env[at + lo]) / width, R(0.0), R(0.99999)) : R(0.5);
    return lo;
}

// The density over solid angle with which march_env_sample draws the unit
// direction d: its texel's probability times the texels per unit of
// image area, over the area's solid angle 2 pi^2 sin(theta).
real march_env_pdf(__global const float* env, real3 d) {
    int w = (int)env[ENV_WIDTH];
    int h = (int)env[ENV_HEIGHT];
    real2 uv = march_env_uv(env, d);
    int x = clamp((int)(uv.x * (real)w), 0, w - 1);
    int y = clamp((int)(uv.y * (real)h), 0, h - 1);
    int row = march_env_conditional(w, h, y);
    int rows = march_env_marginal(w, h);
    real p = ((real)env[rows + y + 1] - (real)env[rows + y])
             * ((real)env[row + x + 1] - (real)env[row + x]);
    real sin_theta = sqrt(fmax(R(1.0) - d.y * d.y, R(0.0)));
    return p * (real)(w * h) / (R(2.0) * MARCH_PI * MARCH_PI * fmax(sin_theta, REAL_TINY));
}

// A direction drawn from the environment in proportion to its texels'
// luminance, from the two uniform numbers u and v; its density in *pdf.
real3 march_env_sample(__global const float* env, real u, real v, real* pdf) {
    int w = (int)env[ENV_WIDTH];
    int h = (int)env[ENV_HEIGHT];
    real fy;
    int y = march_env_find(env, march_env_marginal(w, h), h, u, &fy);
    real fx;
    int x = march_env_find(env, march_env_conditional(w, h, y), w, v, &fx);
    real2 uv = (real2)(((real)x + fx) / (real)w, ((real)y + fy) / (real)h);
    real phi = (uv.x - R(0.5)) * R(2.0) * MARCH_PI;
    real theta = uv.y * MARCH_PI;
    real3 own = (real3)(sin(theta) * sin(phi), cos(theta), -sin(theta) * cos(phi));
    // Into the scene's frame: turned by the rotation about +Y.
    real c = (real)env[ENV_ROTATION_COS];
    real s = (real)env[ENV_ROTATION_SIN];
    real3 d = (real3)(c * own.x + s * own.z, own.y, -s * own.x + c * own.z);
    *pdf = march_env_pdf(env, d);
    return d;
}
#endif

// A direction towards the sphere light l (kind 2) seen from p,
// drawn uniformly within the cone the ball fills from the two uniform
// numbers u and v: the direction in *to_light, the distance to the ball's
// near side along it in *light_distance, and the light it brings over the
// density it was drawn with, over pi. The ball's radiance is the light's over its
// radius squared, so that it lights a face as a point light of its
// radiance at its centre would wherever the whole ball is in view. No
// light from inside the ball.
real3 march_sphere_light(__global const real* l, real3 p, real u, real v, real3* to_light,
                         real* light_distance) {
    real3 delta = vload3(0, l + LIGHT_POSITION) - p;
    real r = l[LIGHT_RADIUS];
    real d2 = dot(delta, delta);
    *to_light = (real3)(R(0.0), R(1.0), R(0.0));
    *light_distance = R(0.0);
    if (d2 <= r * r) {
        return (real3)(R(0.0));
    }
    real d = sqrt(d2);
    real sin2 = r * r / d2;
    real cos_max = sqrt(R(1.0) - sin2);
    // 1 - cos_max, without cancelling for a small ball far away.
    real solid = sin2 / (R(1.0) + cos_max);
    real3 dir = march_around(delta / d, R(1.0) - u * solid, v);
    real b = dot(dir, delta);
    *to_light = dir;
    *light_distance = b - sqrt(fmax(b * b - (d2 - r * r), R(0.0)));
    // The radiance over r^2, over the density 1 / (2 pi solid), and over
    // pi, as march_light's radiances are (see the units above): the r^2
    // cancels, leaving no quotient to overflow for a tiny ball.
    return vload3(0, l + LIGHT_RADIANCE) * (R(2.0) / (d2 * (R(1.0) + cos_max)));
}

// A direction towards a point of the rectangle light l (kind 3) seen from
// p, the point drawn uniformly over its area from the two uniform numbers
// u and v: the direction in *to_light, the distance in *light_distance,
// and the light it brings over the density it was drawn with, over pi.
// The rectangle's radiance is pi times the light's over its area, so that
// its estimate is the light's times the cosine it is seen at over the
// squared distance: a point light at its centre, seen square on from far
// away. It shines on the side u x v faces.
real3 march_rect_light(__global const real* l, real3 p, real u, real v, real3* to_light,
                       real* light_distance) {
    real3 edge_u = vload3(0, l + LIGHT_EDGE_U);
    real3 edge_v = vload3(0, l + LIGHT_EDGE_V);
    real3 q = vload3(0, l + LIGHT_POSITION) + (R(2.0) * u - R(1.0)) * edge_u
              + (R(2.0) * v - R(1.0)) * edge_v;
    real3 delta = q - p;
    real d2 = fmax(dot(delta, delta), REAL_TINY);
    real d = sqrt(d2);
    // The unit normal from the unit sides: no product of two tiny lengths.
    real3 face = cross(normalize(edge_u), normalize(edge_v));
    *to_light = delta / d;
    *light_distance = d;
    real seen = -dot(face, *to_light);
    return seen > R(0.0) ? vload3(0, l + LIGHT_RADIANCE) * (seen / d2) : (real3)(R(0.0));
}

// The light the surface at p gives off: its albedo times its material's
// emission (none without materials).
real3 march_emission(real3 p, __global const real* params, uint* evals) {
#ifdef ENABLE_MATERIALS
    real16 material;
    DE_material(p, params, &material);
    *evals += 1u;
    if (material.MATERIAL_EMISSION > R(0.0)) {
        real3 albedo;
        real2 trap;
        DE_shade(p, params, &albedo, &trap);
        *evals += 1u;
        return albedo * march_trap_tint(trap.x) * material.MATERIAL_EMISSION;
    }
#endif
    return (real3)(R(0.0));
}

#ifdef ENABLE_EMITTERS
// The cone of emitter e's bounding sphere (EMITTER_BOUNDS) seen from o:
// its unit axis, and 1 - cos of its half-angle (as sin^2 / (1 + cos), no
// cancellation for a small one); 0 where o is inside the sphere.
int march_emitter_cone(int e, real3 o, real3* axis, real* one_minus_cos) {
    real4 b = EMITTER_BOUNDS[e];
    real3 to = b.xyz - o;
    real d2 = dot(to, to);
    real r2 = b.w * b.w;
    if (d2 <= r2) {
        return 0;
    }
    real sin2 = r2 / d2;
    *axis = to / sqrt(d2);
    *one_minus_cos = sin2 / (R(1.0) + sqrt(R(1.0) - sin2));
    return 1;
}

// The sum of the squares of the densities with which the emitters'
// sampling (one direction in each one's cone) draws the direction d from
// o: what the power heuristic weighs a direction against.
real march_emitters_pdf2(real3 o, real3 d) {
    real sum = R(0.0);
    for (int e = 0; e < EMITTERS; ++e) {
        real3 axis;
        real omc;
        if (march_emitter_cone(e, o, &axis, &omc) && dot(d, axis) >= R(1.0) - omc) {
            real pdf = R(1.0) / (R(2.0) * GI_PI * omc);
            sum += pdf * pdf;
        }
    }
    return sum;
}
#endif

// Next-event estimation at the surface point p (normal n facing the path,
// hit threshold eps, `travelled` from the camera) reached along rd on
// bounce `bounce` of sample j of the pixel: the light of every light that
// sees p, through the surface's scattering (a sphere or rectangle light
// from a point of it drawn at random), with an environment a direction drawn from
// it by importance, and with emissive shapes (ENABLE_EMITTERS) a direction
// in each one's bounding cone, each weighted against the surface's own
// sampling of the same direction by the power heuristic (march_path traces
// that sampling at every surface, the last included).
real3 march_direct(real3 p, real3 n, real3 rd, real eps, real travelled, const MarchCamera* cam,
                   real3 albedo, real ks, real shininess, real sigma, uint pixel, uint j,
                   int bounce, __global const real* params, __global const real* lights,
                   int light_count, __global const float* environment, uint* evals) {
    real3 sum = (real3)(R(0.0));
#ifdef ENABLE_ENVIRONMENT
    if (environment[ENV_TOTAL] > 0.0f) {
        real pdf;
        real3 d = march_env_sample(environment, march_random(pixel, j, bounce, 5u),
                                   march_random(pixel, j, bounce, 6u), &pdf);
        real ndl = dot(n, d);
        if (ndl > R(0.0) && pdf > R(0.0)) {
            real3 lifted = p + n * (R(2.0) * eps);
            if (march_visible(lifted, d, MAX_DISTANCE, cam, travelled, params, evals)) {
                real weight = march_power_heuristic(pdf, march_brdf_pdf(n, rd, d, ks, shininess));
                sum += march_environment_texel(environment, d)
                       * march_brdf(n, d, rd, albedo, ks, shininess, sigma, ndl)
                       * (ndl * weight / (GI_PI * pdf));
            }
        }
    }
#endif
#ifdef ENABLE_EMITTERS
    // Each emissive shape's bounding sphere: a direction drawn in its cone,
    // and whatever gives off light where that ray hits, weighted against
    // the surface's own sampling and the other emitters' by the power
    // heuristic.
    for (int e = 0; e < EMITTERS; ++e) {
        real3 axis;
        real omc;
        if (!march_emitter_cone(e, p, &axis, &omc)) {
            continue;
        }
        uint own = j ^ march_hash(0x85ebca6bu * (uint)(e + 1));
        real cos_t = R(1.0) - march_random(pixel, own, bounce, 5u) * omc;
        real3 d = march_around(axis, cos_t, march_random(pixel, own, bounce, 6u));
        real ndl = dot(n, d);
        if (ndl <= R(0.0)) {
            continue;
        }
        real3 lifted = p + n * (R(2.0) * eps);
        MarchCamera along = *cam;
        along.footprint_base = march_footprint(cam, travelled);
        MarchResult m = march_ray(lifted, d, R(0.0), &along, R(1.0), params);
        *evals += (uint)m.steps;
        if (!m.hit) {
            continue;
        }
        real3 emitted = march_emission(lifted + d * m.t, params, evals);
        if (!(emitted.x + emitted.y + emitted.z > R(0.0))) {
            continue;
        }
        real pdf = R(1.0) / (R(2.0) * GI_PI * omc);
        real drawn = march_brdf_pdf(n, rd, d, ks, shininess);
        real others = sqrt(fmax(drawn * drawn + march_emitters_pdf2(p, d) - pdf * pdf, R(0.0)));
        sum += emitted * march_brdf(n, d, rd, albedo, ks, shininess, sigma, ndl)
               * (ndl * march_power_heuristic(pdf, others) / (GI_PI * pdf));
    }
#endif
    for (int i = 0; i < light_count; ++i) {
        __global const real* l = lights + LIGHT_STRIDE * i;
        real3 to_light;
        real light_distance;
        real3 radiance = march_light(l, p, &to_light, &light_distance);
        // Each light its own numbers: the sample's mixed with its index.
        uint own = j ^ march_hash(0x9e3779b9u * (uint)(i + 1));
        if (l[LIGHT_KIND] > R(2.5)) {
            radiance = march_rect_light(l, p, march_random(pixel, own, bounce, 5u),
                                        march_random(pixel, own, bounce, 6u), &to_light,
                                        &light_distance);
        } else if (l[LIGHT_KIND] > R(1.5)) {
            radiance = march_sphere_light(l, p, march_random(pixel, own, bounce, 5u),
                                          march_random(pixel, own, bounce, 6u), &to_light,
                                          &light_distance);
        }
        real ndl = dot(n, to_light);
        if (ndl <= R(0.0)) {
            continue;
        }
        real3 lifted = p + n * (R(2.0) * eps);
        if (march_visible(lifted, to_light, light_distance, cam, travelled, params, evals)) {
            sum += radiance * march_brdf(n, to_light, rd, albedo, ks, shininess, sigma, ndl) * ndl;
        }
    }
    return sum;
}

// The light a path brings to the camera from its first hit: the surface
// point p (normal n, facing the ray) reached t along rd, for sample j of
// the pixel. Each surface the path meets chooses, by chance in proportion
// to its material's shares, a mirror reflection, a refraction into a
// transparent shape, or its own scattering; the last adds the lights'
// direct light and bounces on, diffusely (cosine-weighted) or into the
// Phong lobe, with weights that keep the estimate's mean the integral.
// Inside a transparent shape the path travels clear to where it leaves,
// refracting out or reflecting back in on total internal reflection. The
// path meets at most GI_BOUNCES surfaces after the first: each one's light
// is counted (its emission, the lights' sampled at it, the sky's and the
// next surface's emission along its bounce), and the path ends at the next
// surface. Adds its evaluations to *evals.
real3 march_path(real3 p, real3 n, real3 rd, real t, const MarchCamera* cam, uint pixel, uint j,
                 __global const real* params, __global const real* lights, int light_count,
                 __global const float* environment, uint* evals) {
    real3 radiance = (real3)(R(0.0));
    real3 throughput = (real3)(R(1.0));
    real travelled = t;
    int inside = 0;
    // The density the surface's scattering drew the path's last direction
    // with, 0 for a mirror or a refraction: where the path then leaves,
    // the environment's light is weighted against its own sampling.
    real drawn = R(0.0);
    // Where the ray that reached p left from.
    real3 from = p;
    for (int bounce = 0;; ++bounce) {
        real eps = DETAIL * march_footprint(cam, travelled);
        real choose = march_random(pixel, j, bounce, 0u);
        real3 next = rd;
        real3 ro = p;
        // The surface point the next ray scatters from.
        real3 at = p;
        // The density the surface before drew the ray to p with.
        real arrived = drawn;
        drawn = R(0.0);
        if (inside) {
            // Leaving a transparent shape: n is its outward normal.
            real ior = R(1.0);
#ifdef ENABLE_MATERIALS
            real16 material;
            DE_material(p, params, &material);
            *evals += 1u;
            ior = material.MATERIAL_IOR;
            next = march_refract(rd, -n, ior);
#endif
            if (dot(next, next) > R(0.0)) {
                next = normalize(next);
                ro = p + n * (R(2.0) * eps);
                inside = 0;
            } else {
                next = rd - R(2.0) * dot(rd, n) * n;
                ro = p - n * (R(2.0) * eps);
            }
        } else {
            real3 albedo;
            real2 trap;
            DE_shade(p, params, &albedo, &trap);
            *evals += 1u;
            albedo *= march_trap_tint(trap.x);
            real ks = MARCH_SPECULAR;
            real shininess = MARCH_SHININESS;
            real sigma = R(0.0);
            // The shares of a mirror reflection and of a refraction.
            real reflected = R(0.0);
            real passed = R(0.0);
            real3 bent = (real3)(R(0.0));
#ifdef ENABLE_MATERIALS
            real16 material;
            DE_material(p, params, &material);
            *evals += 1u;
            ks = material.MATERIAL_SPECULAR;
            shininess = material.MATERIAL_SHININESS;
            sigma = material.MATERIAL_ROUGHNESS;
            real r = material.MATERIAL_REFLECTIVITY;
            real tau = material.MATERIAL_TRANSPARENCY;
            reflected = r;
            real3 emitted = albedo * material.MATERIAL_EMISSION;
#ifdef ENABLE_EMITTERS
            // Light the emitters' sampling could have found too.
            if (arrived > R(0.0)) {
                emitted *= march_power_heuristic(arrived, sqrt(march_emitters_pdf2(from, rd)));
            }
#endif
            radiance += throughput * emitted;
            if (tau > R(0.0)) {
                real ior = material.MATERIAL_IOR;
                real fresnel = march_fresnel(clamp(-dot(n, rd), R(0.0), R(1.0)), ior);
                bent = march_refract(rd, n, R(1.0) / ior);
                if (dot(bent, bent) > R(0.0)) {
                    passed = (R(1.0) - r) * tau * (R(1.0) - fresnel);
                    reflected += (R(1.0) - r) * tau * fresnel;
                } else {
                    reflected += (R(1.0) - r) * tau;
                }
            }
#endif
            ks = clamp(ks, R(0.0), R(1.0));
            if (choose < reflected) {
                next = rd - R(2.0) * dot(rd, n) * n;
                ro = p + n * (R(2.0) * eps);
            } else if (choose < reflected + passed) {
                next = normalize(bent);
                ro = p - n * (R(2.0) * eps);
                inside = 1;
            } else {
                radiance += throughput * march_direct(p, n, rd, eps, travelled, cam, albedo, ks,
                                                      shininess, sigma, pixel, j, bounce, params,
                                                      lights, light_count, environment, evals);
                real u = march_random(pixel, j, bounce, 1u);
                real v = march_random(pixel, j, bounce, 2u);
                // The lobe by its share: each estimate is then the lobe's
                // BRDF times n.l over its density, divided by the share.
                if (march_random(pixel, j, bounce, 3u) < ks) {
                    real3 mirror = rd - R(2.0) * dot(rd, n) * n;
                    next = march_around(mirror, pow(u, R(1.0) / (shininess + R(1.0))), v);
                    real ndl = dot(n, next);
                    if (ndl <= R(0.0)) {
                        break;
                    }
                    throughput *= (shininess + R(2.0)) / (shininess + R(1.0)) * ndl;
                } else {
                    next = march_around(n, sqrt(u), v);
                    real3 diffuse = albedo;
#ifdef ENABLE_MATERIALS
                    diffuse *= march_oren_nayar(sigma, n, next, -rd, fmax(dot(n, next), R(1e-4)));
#endif
                    throughput *= diffuse;
                }
                drawn = march_brdf_pdf(n, rd, next, ks, shininess);
                ro = p + n * (R(2.0) * eps);
            }
        }
        if (bounce >= GI_ROULETTE) {
            real survive = clamp(fmax(throughput.x, fmax(throughput.y, throughput.z)),
                                 GI_SURVIVE_MIN, GI_SURVIVE_MAX);
            if (march_random(pixel, j, bounce, 4u) >= survive) {
                break;
            }
            throughput /= survive;
        }
        MarchCamera along = *cam;
        along.footprint_base = march_footprint(cam, travelled);
        MarchResult m = march_ray(ro, next, R(0.0), &along, inside ? R(-1.0) : R(1.0), params);
        *evals += (uint)m.steps;
        if (!m.hit) {
            if (!inside) {
                real3 sky = march_sky(next, environment);
#ifdef ENABLE_ENVIRONMENT
                // Light that a bounce off the surface found, where the
                // lights' sampling could have found it too.
                if (drawn > R(0.0) && environment[ENV_TOTAL] > 0.0f) {
                    sky = march_environment_texel(environment, next)
                          * march_power_heuristic(drawn, march_env_pdf(environment, next));
                }
#endif
                radiance += throughput * sky;
            }
            break;
        }
        rd = next;
        p = ro + rd * m.t;
        // The last surface's light is counted (the lights' at it, and the
        // sky's and emitters' beyond it): a path ends at the surface after
        // it.
        if (bounce >= GI_BOUNCES) {
            if (!inside) {
                real3 emitted = march_emission(p, params, evals);
#ifdef ENABLE_EMITTERS
                if (drawn > R(0.0)) {
                    emitted *= march_power_heuristic(drawn, sqrt(march_emitters_pdf2(at, rd)));
                }
#endif
                radiance += throughput * emitted;
            }
            break;
        }
        from = at;
        travelled += m.t;
        real footprint = march_footprint(&along, m.t);
        n = march_normal(p, NORMAL_EPSILON * footprint, rd, params);
        *evals += MARCH_NORMAL_EVALUATIONS;
        if (!inside) {
            n = march_facing(n, rd);
        }
    }
    return radiance;
}
#endif
