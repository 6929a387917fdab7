// Path-traced global illumination in WGSL: kernels/paths.cl, line for
// line. Each sample's first hit starts a path that bounces through the
// scene, sampling the lights, the environment and the emissive shapes at
// every surface it meets (next-event estimation; the environment's and
// the emissive shapes' weighted against the surface's own sampling by the
// power heuristic) and bringing the sky's light where it leaves. The units are paths.cl's: a light's radiance is
// the light a white Lambertian surface facing it sends back, so a surface
// lit by one light has the same colour with and without paths.
//
// Follows render.wgsl (march_light, march_sky, march_fresnel,
// march_refract, march_oren_nayar, the environment's lookups and the
// random numbers), and is part of the module only where global
// illumination is on. The module defines before it GI_BOUNCES, EMITTERS
// (the emissive shapes sampled, at most 16) and emitter_bound(e), the
// bounding sphere of emitter e as (centre, radius).

const GI_ROULETTE: int = 3;           // bounces after which a path may end
const GI_SURVIVE_MIN: real = 0.05;    // the least and most chance a path
const GI_SURVIVE_MAX: real = 0.95;    // has of surviving the roulette
const GI_PI: real = 3.14159265358979324;

// Random number k of bounce `bounce` of sample j of a pixel, in [0, 1):
// independent of the numbers that place the sample in the pixel and on
// the lens.
fn march_random(pixel: uint, j: uint, bounce: int, k: uint) -> real {
    return march_jitter(pixel, j, 16u + 8u * uint(bounce) + k);
}

// The unit vector at polar angle acos(cos_theta) from the unit vector n,
// turned by 2 pi u about it (Duff et al.'s orthonormal basis, 2017).
fn march_around(n: real3, cos_theta: real, u: real) -> real3 {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let c = n.x * n.y * a;
    let t = real3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
    let b = real3(c, s + n.y * n.y * a, -n.y);
    let sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
    let phi = 2.0 * GI_PI * u;
    return t * (sin_theta * cos(phi)) + b * (sin_theta * sin(phi)) + n * cos_theta;
}

// The footprint of a ray that starts `travelled` from the camera.
fn march_along(cam: MarchCamera, travelled: real) -> real2 {
    return real2(march_footprint(cam.footprint, travelled), cam.footprint.y);
}

// Whether nothing blocks the segment from ro along the unit rd up to
// max_t: the same march as the path's rays.
fn march_visible(ro: real3, rd: real3, max_t: real, cam: MarchCamera, travelled: real,
                 evals: ptr<function, uint>) -> bool {
    let m = march_ray(ro, rd, 0.0, march_along(cam, travelled), 1.0);
    *evals += uint(m.steps);
    return !m.hit || m.t >= max_t;
}

// The lobe of a normalised Phong highlight of exponent `shininess` at
// cosine c from the mirror direction (nothing behind it; pow(0, 0) is 1).
fn march_lobe(c: real, shininess: real) -> real {
    if (c <= 0.0) {
        return 0.0;
    }
    if (shininess == 0.0) {
        return 1.0;
    }
    return pow(c, shininess);
}

// The surface's scattering, as a BRDF times pi: the diffuse share
// (1 - ks) albedo (Oren-Nayar's factor for roughness sigma) plus the
// specular share ks of a normalised Phong lobe about the mirror direction
// of the view. n.l is left to the caller.
fn march_brdf(n: real3, to_light: real3, rd: real3, albedo: real3, ks: real, shininess: real,
              sigma: real, ndl: real) -> real3 {
    var diffuse = albedo * (1.0 - ks);
    if (ENABLE_MATERIALS) {
        diffuse *= march_oren_nayar(sigma, n, to_light, -rd, ndl);
    }
    let mirror = rd - 2.0 * dot(rd, n) * n;
    let lobe = march_lobe(dot(mirror, to_light), shininess);
    return diffuse + ks * (shininess + 2.0) * 0.5 * lobe;
}

// The density, over solid angle, with which the surface's scattering
// sends a path leaving along d: the diffuse share's cosine lobe and the
// specular share's Phong lobe.
fn march_brdf_pdf(n: real3, rd: real3, d: real3, ks: real, shininess: real) -> real {
    let ndl = dot(n, d);
    if (ndl <= 0.0) {
        return 0.0;
    }
    let mirror = rd - 2.0 * dot(rd, n) * n;
    let lobe = march_lobe(dot(mirror, d), shininess);
    return ((1.0 - ks) * ndl + ks * (shininess + 1.0) * 0.5 * lobe) / GI_PI;
}

// Veach's power heuristic, a^2 / (a^2 + b^2), by the ratio of the smaller
// to the larger density (no overflow near the environment's poles).
fn march_power_heuristic(a: real, b: real) -> real {
    if (!(a > 0.0)) {
        return 0.0;
    }
    if (a >= b) {
        let r = b / a;
        return 1.0 / (1.0 + r * r);
    }
    let r = a / b;
    return r * r / (1.0 + r * r);
}

// The environment's radiance along d at its nearest texel: what its
// importance sampling draws.
fn march_environment_texel(d: real3) -> real3 {
    let w = int(environment[ENV_WIDTH]);
    let h = int(environment[ENV_HEIGHT]);
    let uv = march_env_uv(d);
    let x = clamp(int(uv.x * real(w)), 0, w - 1);
    let y = clamp(int(uv.y * real(h)), 0, h - 1);
    return march_env_texel(int(ENV_TEXELS), w, x, y) * environment[ENV_INTENSITY];
}

// Where the marginal distribution of rows, and row y's conditional
// distribution, start (codegen::interface::environment): cumulative
// sums, 0 first and 1 last.
fn march_env_marginal(w: int, h: int) -> int {
    return int(ENV_TEXELS) + 3 * w * h;
}

fn march_env_conditional(w: int, h: int, row: int) -> int {
    return march_env_marginal(w, h) + (h + 1) + row * (w + 1);
}

// The bin of the n + 1 cumulative sums at `at` that holds u, and where in
// it u lies (in [0, 1)).
struct Bin {
    index: int,
    frac: real,
}

fn march_env_find(at: int, n: int, u: real) -> Bin {
    var lo = 0;
    var hi = n;
    while (hi - lo > 1) {
        let mid = (lo + hi) / 2;
        if (environment[at + mid] <= u) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let low = environment[at + lo];
    let width = environment[at + lo + 1] - low;
    var frac = 0.5;
    if (width > 0.0) {
        frac = clamp((u - low) / width, 0.0, 0.99999);
    }
    return Bin(lo, frac);
}

// The density over solid angle with which march_env_sample draws the unit
// direction d.
fn march_env_pdf(d: real3) -> real {
    let w = int(environment[ENV_WIDTH]);
    let h = int(environment[ENV_HEIGHT]);
    let uv = march_env_uv(d);
    let x = clamp(int(uv.x * real(w)), 0, w - 1);
    let y = clamp(int(uv.y * real(h)), 0, h - 1);
    let row = march_env_conditional(w, h, y);
    let rows = march_env_marginal(w, h);
    let p = (environment[rows + y + 1] - environment[rows + y])
            * (environment[row + x + 1] - environment[row + x]);
    let sin_theta = sqrt(max(1.0 - d.y * d.y, 0.0));
    return p * real(w * h) / (2.0 * MARCH_PI * MARCH_PI * max(sin_theta, REAL_TINY));
}

// A direction drawn from the environment in proportion to its texels'
// luminance, from the uniform numbers u and v, and its density.
struct Drawn {
    d: real3,
    pdf: real,
}

fn march_env_sample(u: real, v: real) -> Drawn {
    let w = int(environment[ENV_WIDTH]);
    let h = int(environment[ENV_HEIGHT]);
    let row = march_env_find(march_env_marginal(w, h), h, u);
    let column = march_env_find(march_env_conditional(w, h, row.index), w, v);
    let uv = real2((real(column.index) + column.frac) / real(w),
                   (real(row.index) + row.frac) / real(h));
    let phi = (uv.x - 0.5) * 2.0 * MARCH_PI;
    let theta = uv.y * MARCH_PI;
    let own = real3(sin(theta) * sin(phi), cos(theta), -sin(theta) * cos(phi));
    // Into the scene's frame: turned by the rotation about +Y.
    let c = environment[ENV_ROTATION_COS];
    let s = environment[ENV_ROTATION_SIN];
    let d = real3(c * own.x + s * own.z, own.y, -s * own.x + c * own.z);
    return Drawn(d, march_env_pdf(d));
}

// A direction towards the sphere light at `at` seen from p, drawn
// uniformly within the cone the ball fills: the direction, the distance
// to the ball's near side along it, and the light it brings over the
// density it was drawn with, over pi (paths.cl's march_sphere_light).
fn march_sphere_light(at: uint, p: real3, u: real, v: real) -> LightSample {
    let delta = light_vector(at + LIGHT_POSITION) - p;
    let r = lights[at + LIGHT_RADIUS];
    let d2 = dot(delta, delta);
    if (d2 <= r * r) {
        return LightSample(real3(0.0, 1.0, 0.0), 0.0, real3(0.0));
    }
    let d = sqrt(d2);
    let sin2 = r * r / d2;
    let cos_max = sqrt(1.0 - sin2);
    // 1 - cos_max, without cancelling for a small ball far away.
    let solid = sin2 / (1.0 + cos_max);
    let dir = march_around(delta / d, 1.0 - u * solid, v);
    let b = dot(dir, delta);
    let distance = b - sqrt(max(b * b - (d2 - r * r), 0.0));
    return LightSample(dir, distance,
                       light_vector(at + LIGHT_RADIANCE) * (2.0 / (d2 * (1.0 + cos_max))));
}

// A direction towards a point of the rectangle light at `at`, drawn
// uniformly over its area (paths.cl's march_rect_light).
fn march_rect_light(at: uint, p: real3, u: real, v: real) -> LightSample {
    let edge_u = light_vector(at + LIGHT_EDGE_U);
    let edge_v = light_vector(at + LIGHT_EDGE_V);
    let q = light_vector(at + LIGHT_POSITION) + (2.0 * u - 1.0) * edge_u
            + (2.0 * v - 1.0) * edge_v;
    let delta = q - p;
    let d2 = max(dot(delta, delta), REAL_TINY);
    let d = sqrt(d2);
    // The unit normal from the unit sides: no product of two tiny lengths.
    let face = cross(normalize(edge_u), normalize(edge_v));
    let to_light = delta / d;
    let seen = -dot(face, to_light);
    var radiance = real3(0.0);
    if (seen > 0.0) {
        radiance = light_vector(at + LIGHT_RADIANCE) * (seen / d2);
    }
    return LightSample(to_light, d, radiance);
}

// The light the surface at p gives off: its albedo times its material's
// emission (none without materials).
fn march_emission(p: real3, evals: ptr<function, uint>) -> real3 {
    if (!ENABLE_MATERIALS) {
        return real3(0.0);
    }
    var material: real16;
    DE_material(p, &material);
    *evals += 1u;
    let emission = material_value(material, MATERIAL_EMISSION);
    if (emission > 0.0) {
        var albedo: real3;
        var trap: real2;
        DE_shade(p, &albedo, &trap);
        *evals += 1u;
        return albedo * march_trap_tint(trap.x) * emission;
    }
    return real3(0.0);
}

// The cone of emitter e's bounding sphere seen from o: its unit axis and
// 1 - cos of its half-angle; none (w 0) where o is inside the sphere.
fn march_emitter_cone(e: int, o: real3) -> real4 {
    let b = emitter_bound(e);
    let to = b.xyz - o;
    let d2 = dot(to, to);
    let r2 = b.w * b.w;
    if (d2 <= r2) {
        return real4(0.0);
    }
    let sin2 = r2 / d2;
    return real4(to / sqrt(d2), sin2 / (1.0 + sqrt(1.0 - sin2)));
}

// The sum of the squares of the densities with which the emitters'
// sampling draws the direction d from o.
fn march_emitters_pdf2(o: real3, d: real3) -> real {
    var sum = 0.0;
    for (var e = 0; e < EMITTERS; e++) {
        let cone = march_emitter_cone(e, o);
        if (cone.w > 0.0 && dot(d, cone.xyz) >= 1.0 - cone.w) {
            let pdf = 1.0 / (2.0 * GI_PI * cone.w);
            sum += pdf * pdf;
        }
    }
    return sum;
}

// A surface's scattering where a path meets it.
struct Surface {
    albedo: real3,
    ks: real,
    shininess: real,
    sigma: real,
}

// Next-event estimation at the surface point p (normal n facing the path,
// hit threshold eps, `travelled` from the camera) reached along rd on
// bounce `bounce` of sample j of the pixel (paths.cl's march_direct): the
// environment (a direction drawn by importance), each emissive shape (a
// direction in its bounding cone) and every light, through the surface's
// scattering, the first two weighted against the surface's own sampling.
fn march_direct(p: real3, n: real3, rd: real3, eps: real, travelled: real, cam: MarchCamera,
                s: Surface, pixel: uint, j: uint, bounce: int,
                evals: ptr<function, uint>) -> real3 {
    var sum = real3(0.0);
    let lifted = p + n * (2.0 * eps);
    if (ENABLE_ENVIRONMENT && environment[ENV_TOTAL] > 0.0) {
        let drawn = march_env_sample(march_random(pixel, j, bounce, 5u),
                                     march_random(pixel, j, bounce, 6u));
        let ndl = dot(n, drawn.d);
        if (ndl > 0.0 && drawn.pdf > 0.0
            && march_visible(lifted, drawn.d, MAX_DISTANCE, cam, travelled, evals)) {
            let weight = march_power_heuristic(
                drawn.pdf, march_brdf_pdf(n, rd, drawn.d, s.ks, s.shininess));
            sum += march_environment_texel(drawn.d)
                   * march_brdf(n, drawn.d, rd, s.albedo, s.ks, s.shininess, s.sigma, ndl)
                   * (ndl * weight / (GI_PI * drawn.pdf));
        }
    }
    for (var e = 0; e < EMITTERS; e++) {
        let cone = march_emitter_cone(e, p);
        if (cone.w <= 0.0) {
            continue;
        }
        let own = j ^ march_hash(0x85ebca6bu * uint(e + 1));
        let cos_t = 1.0 - march_random(pixel, own, bounce, 5u) * cone.w;
        let d = march_around(cone.xyz, cos_t, march_random(pixel, own, bounce, 6u));
        let ndl = dot(n, d);
        if (ndl <= 0.0) {
            continue;
        }
        let m = march_ray(lifted, d, 0.0, march_along(cam, travelled), 1.0);
        *evals += uint(m.steps);
        if (!m.hit) {
            continue;
        }
        let emitted = march_emission(lifted + d * m.t, evals);
        if (!(emitted.x + emitted.y + emitted.z > 0.0)) {
            continue;
        }
        let pdf = 1.0 / (2.0 * GI_PI * cone.w);
        let drawn = march_brdf_pdf(n, rd, d, s.ks, s.shininess);
        let others = sqrt(max(drawn * drawn + march_emitters_pdf2(p, d) - pdf * pdf, 0.0));
        sum += emitted * march_brdf(n, d, rd, s.albedo, s.ks, s.shininess, s.sigma, ndl)
               * (ndl * march_power_heuristic(pdf, others) / (GI_PI * pdf));
    }
    for (var i = 0u; i < frame.light_count; i++) {
        let at = LIGHT_STRIDE * i;
        var l = march_light(i, p);
        // Each light its own numbers: the sample's mixed with its index.
        let own = j ^ march_hash(0x9e3779b9u * (i + 1u));
        let kind = lights[at + LIGHT_KIND];
        if (kind > 2.5) {
            l = march_rect_light(at, p, march_random(pixel, own, bounce, 5u),
                                 march_random(pixel, own, bounce, 6u));
        } else if (kind > 1.5) {
            l = march_sphere_light(at, p, march_random(pixel, own, bounce, 5u),
                                   march_random(pixel, own, bounce, 6u));
        }
        let ndl = dot(n, l.to_light);
        if (ndl <= 0.0) {
            continue;
        }
        if (march_visible(lifted, l.to_light, l.distance, cam, travelled, evals)) {
            sum += l.radiance
                   * march_brdf(n, l.to_light, rd, s.albedo, s.ks, s.shininess, s.sigma, ndl)
                   * ndl;
        }
    }
    return sum;
}

// The light a path brings to the camera from its first hit: the surface
// point p (normal n, facing the ray) reached t along rd, for sample j of
// the pixel (paths.cl's march_path). Each surface the path meets chooses,
// by chance in proportion to its material's shares, a mirror reflection,
// a refraction into a transparent shape, or its own scattering; the last
// adds the direct light and bounces on, diffusely or into the Phong lobe.
// The path meets at most GI_BOUNCES surfaces after the first. Adds its
// evaluations to *evals.
fn march_path(p_in: real3, n_in: real3, rd_in: real3, t: real, cam: MarchCamera, pixel: uint,
              j: uint, evals: ptr<function, uint>) -> real3 {
    var p = p_in;
    var n = n_in;
    var rd = rd_in;
    var radiance = real3(0.0);
    var throughput = real3(1.0);
    var travelled = t;
    var inside = false;
    // The density the surface's scattering drew the path's last direction
    // with, 0 for a mirror or a refraction.
    var drawn = 0.0;
    // Where the ray that reached p left from.
    var came_from = p;
    for (var bounce = 0; ; bounce++) {
        let eps = DETAIL * march_footprint(cam.footprint, travelled);
        let choose = march_random(pixel, j, bounce, 0u);
        var next = rd;
        var ro = p;
        // The surface point the next ray scatters from.
        let at = p;
        // The density the surface before drew the ray to p with.
        let arrived = drawn;
        drawn = 0.0;
        if (inside) {
            // Leaving a transparent shape: n is its outward normal.
            if (ENABLE_MATERIALS) {
                var material: real16;
                DE_material(p, &material);
                *evals += 1u;
                next = march_refract(rd, -n, material_value(material, MATERIAL_IOR));
            }
            if (dot(next, next) > 0.0) {
                next = normalize(next);
                ro = p + n * (2.0 * eps);
                inside = false;
            } else {
                next = rd - 2.0 * dot(rd, n) * n;
                ro = p - n * (2.0 * eps);
            }
        } else {
            var albedo: real3;
            var trap: real2;
            DE_shade(p, &albedo, &trap);
            *evals += 1u;
            albedo *= march_trap_tint(trap.x);
            var s = Surface(albedo, MARCH_SPECULAR, MARCH_SHININESS, 0.0);
            // The shares of a mirror reflection and of a refraction.
            var reflected = 0.0;
            var passed = 0.0;
            var bent = real3(0.0);
            if (ENABLE_MATERIALS) {
                var material: real16;
                DE_material(p, &material);
                *evals += 1u;
                s.ks = material_value(material, MATERIAL_SPECULAR);
                s.shininess = material_value(material, MATERIAL_SHININESS);
                s.sigma = material_value(material, MATERIAL_ROUGHNESS);
                let r = material_value(material, MATERIAL_REFLECTIVITY);
                let tau = material_value(material, MATERIAL_TRANSPARENCY);
                reflected = r;
                var emitted = albedo * material_value(material, MATERIAL_EMISSION);
                // Light the emitters' sampling could have found too.
                if (EMITTERS > 0 && arrived > 0.0) {
                    emitted *= march_power_heuristic(arrived,
                                                     sqrt(march_emitters_pdf2(came_from, rd)));
                }
                radiance += throughput * emitted;
                if (tau > 0.0) {
                    let ior = material_value(material, MATERIAL_IOR);
                    let fresnel = march_fresnel(clamp(-dot(n, rd), 0.0, 1.0), ior);
                    bent = march_refract(rd, n, 1.0 / ior);
                    if (dot(bent, bent) > 0.0) {
                        passed = (1.0 - r) * tau * (1.0 - fresnel);
                        reflected += (1.0 - r) * tau * fresnel;
                    } else {
                        reflected += (1.0 - r) * tau;
                    }
                }
            }
            s.ks = clamp(s.ks, 0.0, 1.0);
            if (choose < reflected) {
                next = rd - 2.0 * dot(rd, n) * n;
                ro = p + n * (2.0 * eps);
            } else if (choose < reflected + passed) {
                next = normalize(bent);
                ro = p - n * (2.0 * eps);
                inside = true;
            } else {
                radiance += throughput * march_direct(p, n, rd, eps, travelled, cam, s, pixel,
                                                      j, bounce, evals);
                let u = march_random(pixel, j, bounce, 1u);
                let v = march_random(pixel, j, bounce, 2u);
                // The lobe by its share: each estimate is then the lobe's
                // BRDF times n.l over its density, divided by the share.
                if (march_random(pixel, j, bounce, 3u) < s.ks) {
                    let mirror = rd - 2.0 * dot(rd, n) * n;
                    next = march_around(mirror, pow(u, 1.0 / (s.shininess + 1.0)), v);
                    let ndl = dot(n, next);
                    if (ndl <= 0.0) {
                        break;
                    }
                    throughput *= (s.shininess + 2.0) / (s.shininess + 1.0) * ndl;
                } else {
                    next = march_around(n, sqrt(u), v);
                    var diffuse = albedo;
                    if (ENABLE_MATERIALS) {
                        diffuse *= march_oren_nayar(s.sigma, n, next, -rd,
                                                    max(dot(n, next), 1e-4));
                    }
                    throughput *= diffuse;
                }
                drawn = march_brdf_pdf(n, rd, next, s.ks, s.shininess);
                ro = p + n * (2.0 * eps);
            }
        }
        if (bounce >= GI_ROULETTE) {
            let survive = clamp(max(throughput.x, max(throughput.y, throughput.z)),
                                GI_SURVIVE_MIN, GI_SURVIVE_MAX);
            if (march_random(pixel, j, bounce, 4u) >= survive) {
                break;
            }
            throughput /= survive;
        }
        let along = march_along(cam, travelled);
        let m = march_ray(ro, next, 0.0, along, select(1.0, -1.0, inside));
        *evals += uint(m.steps);
        if (!m.hit) {
            if (!inside) {
                var sky = march_sky(next);
                // Light that a bounce off the surface found, where the
                // environment's sampling could have found it too.
                if (ENABLE_ENVIRONMENT && drawn > 0.0 && environment[ENV_TOTAL] > 0.0) {
                    sky = march_environment_texel(next)
                          * march_power_heuristic(drawn, march_env_pdf(next));
                }
                radiance += throughput * sky;
            }
            break;
        }
        rd = next;
        p = ro + rd * m.t;
        // The last surface's light is counted: a path ends at the surface
        // after it.
        if (bounce >= GI_BOUNCES) {
            if (!inside) {
                var emitted = march_emission(p, evals);
                if (EMITTERS > 0 && drawn > 0.0) {
                    emitted *= march_power_heuristic(drawn, sqrt(march_emitters_pdf2(at, rd)));
                }
                radiance += throughput * emitted;
            }
            break;
        }
        came_from = at;
        travelled += m.t;
        let footprint = march_footprint(along, m.t);
        n = march_normal(p, NORMAL_EPSILON * footprint, rd);
        *evals += MARCH_NORMAL_EVALUATIONS;
        if (!inside) {
            n = march_facing(n, rd);
        }
    }
    return radiance;
}
