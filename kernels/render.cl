// render.cl — the kernels a render program runs.
//
// Follows paths.cl: the brute-force depth pass of inside shapes
// (ENABLE_BRUTE), the screen-space normals and occlusion of stored depths,
// render_tile (one tile of pixels: march, shade, fog and glow) and the
// coarse pass (ENABLE_CONE: cone_starts).

#ifdef ENABLE_BRUTE
// Where a pixel's brute-force steps start on its sample j, in [0, 1) of a
// step: an offset of its own, advanced by the golden ratio's fraction from
// one sample to the next, so successive passes spread their lattices
// evenly over the step and their mean converges on the set's surface.
real march_brute_phase(uint pixel, uint j) {
    real u = march_jitter(pixel, 0u, 2u) + R(0.61803398874989485) * (real)j;
    return u - floor(u);
}

// The brute-force pass: marches sample s of this pass at every pixel and
// leaves its depth (on a miss, -1 - the angle of its nearest miss, which
// the glow reads: a negative value) and evaluations at
// (s * height + y) * width + x, for render_tile to shade: the normal and
// occlusion of a point of an inside shape need its neighbours' hits.
__kernel void brute_depths(BRUTE_DEPTHS_ARGS) {
    int x = (int)get_global_id(0);
    int y = (int)get_global_id(1);
    if (x >= width || y >= height) {
        return;
    }
    MarchCamera cam = march_load_camera(camera);
    const int per_pass = SUPERSAMPLING * SUPERSAMPLING;
    const uint first = pass > 0 ? (uint)pass * (uint)per_pass : 0u;
    const uint pixel = (uint)y * (uint)width + (uint)x;
    for (int s = 0; s < per_pass; ++s) {
        uint j = first + (uint)s;
        real py;
        real3 ro;
        real3 rd;
        march_sample_ray(&cam, x, y, pixel, j, s, &py, &ro, &rd);
        cam.phase = march_brute_phase(pixel, j);
        MarchResult m = march_ray(ro, rd, R(0.0), &cam, R(1.0), params);
        int at = (s * height + y) * width + x;
        depths[at] = m.hit ? (float)m.t : (float)(R(-1.0) - m.closest);
        steps[at] = (uint)m.steps;
    }
}

// The hit point of sample s (sample j of the image) at rendered pixel
// (x, y), from the depths brute_depths left. Returns 0 where the pixel is
// outside the image or its ray missed.
int march_stored_point(const MarchCamera* cam, __global const float* depths, int x, int y, int s,
                       int width, int height, uint j, real3* p) {
    if (x < 0 || y < 0 || x >= width || y >= height) {
        return 0;
    }
    float t = depths[(s * height + y) * width + x];
    if (t < 0.0f) {
        return 0;
    }
    real py;
    real3 ro;
    real3 rd;
    march_sample_ray(cam, x, y, (uint)y * (uint)width + (uint)x, j, s, &py, &ro, &rd);
    *p = ro + rd * (real)t;
    return 1;
}

// Neighbours whose hit points lie within this many brute-force steps (and
// at least this many footprints) of a pixel's, per pixel between them, are
// on its surface.
#define MARCH_SCREEN_REACH R(6.0)
// The least-squares fit takes the neighbours up to this many pixels away.
#define MARCH_FIT_RADIUS 1

// The hit of sample s at the pixel (dx, dy) away from (x, y), if it lies
// on the same surface as p (see MARCH_SCREEN_REACH), in *q; leaves *q as
// it is where it does not.
int march_neighbour(const MarchCamera* cam, __global const float* depths, int x, int y, int dx,
                    int dy, int s, int width, int height, uint j, real3 p, real reach,
                    real3* q) {
    real3 r;
    if (march_stored_point(cam, depths, x + dx, y + dy, s, width, height, j, &r) &&
        length(r - p) <= reach * (real)max(abs(dx), abs(dy))) {
        *q = r;
        return 1;
    }
    return 0;
}

// The normal at p, the hit of sample s at pixel (x, y) along rd, from its
// neighbours' hits on the same surface. SCREEN_NORMALS 0: the cross
// product of the central differences across the pixel, one-sided where a
// neighbour is elsewhere. 1: Englund's least squares: the plane through
// the hits of the pixels up to MARCH_FIT_RADIUS away, p's among them, that
// best predicts their depth along the view from their offsets across it
// (the jittered steps put their noise in depth); the differences where
// the hits do not span a plane. Faces the viewer; -rd where no plane can
// be found.
real3 march_screen_normal(const MarchCamera* cam, __global const float* depths, int x, int y,
                          int s, int width, int height, uint j, real3 p, real3 rd,
                          real footprint) {
    real reach = MARCH_SCREEN_REACH * fmax(BRUTE_STEP, R(1.0)) * footprint;
    real3 left = p;
    real3 right = p;
    real3 up = p;
    real3 down = p;
    int across = march_neighbour(cam, depths, x, y, -1, 0, s, width, height, j, p, reach, &left);
    across |= march_neighbour(cam, depths, x, y, 1, 0, s, width, height, j, p, reach, &right);
    int along = march_neighbour(cam, depths, x, y, 0, -1, s, width, height, j, p, reach, &up);
    along |= march_neighbour(cam, depths, x, y, 0, 1, s, width, height, j, p, reach, &down);
    // Central differences, or one-sided ones (a missing neighbour is p).
    real3 n = across && along ? cross(right - left, down - up) : (real3)(R(0.0));
    if (SCREEN_NORMALS == 1) {
        const int side = 2 * MARCH_FIT_RADIUS + 1;
        real3 sum = (real3)(R(0.0));
        real3 pts[(2 * MARCH_FIT_RADIUS + 1) * (2 * MARCH_FIT_RADIUS + 1)];
        int ok[(2 * MARCH_FIT_RADIUS + 1) * (2 * MARCH_FIT_RADIUS + 1)];
        real count = R(0.0);
        for (int k = 0; k < side * side; ++k) {
            int dx = k % side - MARCH_FIT_RADIUS;
            int dy = k / side - MARCH_FIT_RADIUS;
            pts[k] = p;
            ok[k] = (dx == 0 && dy == 0) ||
                    march_neighbour(cam, depths, x, y, dx, dy, s, width, height, j, p, reach,
                                    &pts[k]);
            if (ok[k]) {
                sum += pts[k];
                count += R(1.0);
            }
        }
        real3 mean = sum / count;
        real suu = R(0.0);
        real suv = R(0.0);
        real svv = R(0.0);
        real suw = R(0.0);
        real svw = R(0.0);
        for (int k = 0; k < side * side; ++k) {
            if (ok[k]) {
                real3 d = pts[k] - mean;
                real u = dot(d, cam->right);
                real v = dot(d, cam->up);
                real w = dot(d, cam->forward);
                suu += u * u;
                suv += u * v;
                svv += v * v;
                suw += u * w;
                svw += v * w;
            }
        }
        real det = suu * svv - suv * suv;
        if (count >= R(3.0) && det > R(1e-3) * suu * svv) {
            // w = a u + b v: the surface's gradient is (-a, -b, 1).
            real a = (suw * svv - svw * suv) / det;
            real b = (svw * suu - suw * suv) / det;
            n = a * cam->right + b * cam->up - cam->forward;
        }
    }
    real len = length(n);
    if (!(len > REAL_TINY)) {
        return -rd;
    }
    n /= len;
    return dot(n, rd) > R(0.0) ? -n : n;
}

#ifdef ENABLE_AO
#define MARCH_SSAO_SAMPLES 16
// Screen-space ambient occlusion at p, the hit of sample s at pixel
// (x, y), with normal n: MARCH_SSAO_SAMPLES neighbours on a golden-angle
// spiral out to the pixels the occlusion's reach covers (the reach of
// march_ambient_occlusion), each occluding by how far above p's tangent
// plane its hit lies (the cosine of its elevation, less a small bias
// against flat surfaces occluding themselves), fading to nothing at twice
// the reach. 1 on an open face, towards 0 in a crease.
real march_screen_occlusion(const MarchCamera* cam, __global const float* depths, int x, int y,
                            int s, int width, int height, uint j, real3 p, real3 n,
                            real footprint, real view_height) {
    real reach = fmin(AO_DISTANCE, AO_VIEW_FRACTION * view_height);
    real radius = clamp(reach / footprint, R(2.0), R(32.0));
    real turn = R(6.28318530717958648) * march_jitter((uint)y * (uint)width + (uint)x, j, 3u);
    real hidden = R(0.0);
    for (int k = 0; k < MARCH_SSAO_SAMPLES; ++k) {
        real angle = turn + R(2.39996322972865332) * (real)k;
        real r = radius * sqrt(((real)k + R(0.5)) / (real)MARCH_SSAO_SAMPLES);
        int qx = x + (int)rint(r * cos(angle));
        int qy = y + (int)rint(r * sin(angle));
        real3 q;
        if (march_stored_point(cam, depths, qx, qy, s, width, height, j, &q)) {
            real3 v = q - p;
            real d = length(v);
            if (d > REAL_TINY) {
                real rise = fmax(dot(n, v) / d - R(0.1), R(0.0));
                hidden += rise * clamp(R(1.0) - d / (R(2.0) * reach), R(0.0), R(1.0));
            }
        }
    }
    return clamp(R(1.0) - R(2.0) * hidden / (real)MARCH_SSAO_SAMPLES, R(0.0), R(1.0));
}
#endif
#endif

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
#ifdef ENABLE_CONE
    start = starts[(y / CONE_TILE) * ((width + CONE_TILE - 1) / CONE_TILE) + x / CONE_TILE];
#endif

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
#ifdef ENABLE_BRUTE
        stored = 1;
        {
            int at = (s * height + y) * width + x;
            float t = brute_depths[at];
            m.hit = t >= 0.0f;
            m.t = m.hit ? (real)t : R(0.0);
            m.closest = m.hit ? R(0.0) : R(-1.0) - (real)t;
            m.steps = (int)brute_steps[at];
        }
#endif
        if (!stored) {
            m = march_ray(ro, rd, start, &cam, R(1.0), params);
        }
        total_steps += (uint)m.steps;
        total_evals += (uint)m.steps;

        real3 background = march_background(&cam, py);
#ifdef ENABLE_SKY_BACKGROUND
        // The sky that lights the paths, or the environment, seen along
        // the ray.
        background = march_sky(rd, environment);
#endif
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
#ifdef ENABLE_BRUTE
            in_set = DE(p, params) <= R(-0.5) * INSIDE_HUGE;
            total_evals += 1u;
            if (in_set) {
                n = march_screen_normal(&cam, brute_depths, x, y, s, width, height, j, p, rd,
                                        footprint);
            }
#endif
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
#ifdef ENABLE_DIRECT
            // Occlusion samples at the midpoints of their intervals.
            real offset = R(0.5);
#ifdef ENABLE_BRUTE
            // The distance's samples along the normal see inside shapes
            // only where they land in one (a value of -INSIDE_HUGE counts
            // as fully occluded): jittered like the march's steps, so
            // passes average the all-or-nothing samples instead of
            // banding them.
            offset = march_brute_phase(pixel, j);
#endif
            real occlusion = march_occlusion(p, n, view_height, offset, params, &total_evals);
#ifdef ENABLE_BRUTE
#ifdef ENABLE_AO
            // The neighbours' depths add what the screen shows around the
            // hit.
            occlusion *= march_screen_occlusion(&cam, brute_depths, x, y, s, width, height, j, p,
                                                n, footprint, view_height);
#endif
#endif
            real3 emitted;
            color = march_shade(p, n, rd, DETAIL * footprint, occlusion, params, lights,
                                light_count, environment, &emitted, &total_evals);
#ifdef ENABLE_MATERIALS
            color = march_paths(p, n, rd, DETAIL * footprint, m.t, &cam, color, emitted, params,
                                lights, light_count, environment, &total_evals);
#endif
#endif
#ifdef ENABLE_GI
            color = march_path(p, n, rd, fmax(m.t, R(0.0)), &cam, pixel, j, params, lights,
                               light_count, environment, &total_evals);
#endif
#ifdef ENABLE_FOG
            // What the fog takes away, the sky puts back.
            color = mix(background, color, exp(-march_fog_depth(ro, rd, m.t)));
#endif
        }
#ifdef ENABLE_GLOW
        else {
            color += GLOW_COLOR * (GLOW_STRENGTH * exp(-MARCH_GLOW_FALLOFF * m.closest));
#ifdef ENABLE_NODE_GLOW
            // Each glow node's halo, from the angle the ray passed its
            // shape at (none where the rays came marched by brute force).
            for (int k = 0; k < GLOW_NODES && !stored; ++k) {
                color += glow_color(k, params) * exp(-MARCH_GLOW_FALLOFF * m.glow_closest[k]);
            }
#endif
        }
#endif
#ifdef ENABLE_FOG_LIGHT
        color += march_fog_light(ro, rd, m.hit ? fmax(m.t, R(0.0)) : (real)INFINITY,
                                 march_jitter(pixel, j, 4u), &cam, params, lights, light_count,
                                 &total_evals);
#endif
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

#ifdef ENABLE_CONE
#define CONE_STEPS 64 // most evaluations of a tile's cone

// The coarse pass: for each tile of CONE_TILE x CONE_TILE rendered pixels,
// how far every ray of the tile can travel before it could reach the
// drawn surface. A cone around the ray through the tile's centre holds
// every ray through the tile: radius rho0 + tau tan(theta) at tau along its
// axis (rho0 for orthographic cameras, whose rays are parallel; the angle
// for perspective ones, whose rays share an origin). It is sphere-traced
// like a ray, stepping from tau only as far as the ball of radius d (the
// estimate at the axis, less the surface's offset and the glow's margin)
// still holds the cone's slice: a point of the cone at tau' is within
// (tau' - tau) + rho0 + tau' tan(theta) of the axis point, so
// tau' = (d + tau - rho0) / (1 + tan(theta) + k sec(theta)), where k keeps
// the glow (march_glow_slope) and sec(theta) bounds a ray's length over
// its axial distance. A ray of the tile is in the cone up to the distance
// the cone reached, so it starts there.
__kernel void cone_starts(CONE_STARTS_ARGS) {
    int cx = (int)get_global_id(0);
    int cy = (int)get_global_id(1);
    int columns = (width + CONE_TILE - 1) / CONE_TILE;
    int rows = (height + CONE_TILE - 1) / CONE_TILE;
    if (cx >= columns || cy >= rows) {
        return;
    }
    MarchCamera cam = march_load_camera(camera);
    real x0 = (real)(cx * CONE_TILE) * cam.pixel_scale;
    real y0 = (real)(cy * CONE_TILE) * cam.pixel_scale;
    real x1 = (real)min((cx + 1) * CONE_TILE, width) * cam.pixel_scale;
    real y1 = (real)min((cy + 1) * CONE_TILE, height) * cam.pixel_scale;
    real3 ro;
    real3 rd;
    march_camera_ray(&cam, R(0.5) * (x0 + x1), R(0.5) * (y0 + y1), &ro, &rd);
    real rho0 = R(0.0);
    real cos_theta = R(1.0);
    for (int i = 0; i < 4; ++i) {
        real3 o;
        real3 d;
        march_camera_ray(&cam, (i & 1) ? x1 : x0, (i & 2) ? y1 : y0, &o, &d);
        rho0 = fmax(rho0, length(o - ro));
        cos_theta = fmin(cos_theta, dot(d, rd));
    }
    // A margin for the rounding of the corner rays.
    rho0 *= R(1.01);
    cos_theta = clamp(cos_theta - R(1e-6), R(0.1), R(1.0));
    real tan_theta = sqrt(R(1.0) - cos_theta * cos_theta) / cos_theta;
    // A lens of radius a moves each ray off its pinhole ray by
    // a |1 - tau / focus| <= a + tau a / focus at tau along the axis (the
    // lens ray and the pinhole ray meet on the plane in focus): the cone
    // widens by a at its apex and by a / focus in slope.
    if (cam.aperture > R(0.0)) {
        rho0 += cam.aperture;
        tan_theta += cam.aperture / cam.focus;
    }
    real sec_theta = sqrt(R(1.0) + tan_theta * tan_theta);
    real widen = R(1.0) + tan_theta + march_glow_slope() * sec_theta;
    real t = R(0.0);
    for (int i = 0; i < CONE_STEPS; ++i) {
        real d = DE(ro + rd * t, params);
        // The surface lies DETAIL footprints out, measured along a ray at
        // most (t + d) sec(theta) long here (twice that, for margin).
        real reach = d - DETAIL * march_footprint(&cam, R(2.0) * (t + fabs(d)) * sec_theta);
        real next = (reach + t - rho0) / widen;
        if (!(next > t)) {
            break;
        }
        t = next;
        if (t > MAX_DISTANCE) {
            break;
        }
    }
    // Rounded down when stored, so no ray starts beyond it.
    starts[cy * columns + cx] = (float)(t * R(0.999));
}
#endif
