// Inside shapes in WGSL: render.cl's brute-force depth pass and the
// screen-space normals and occlusion of the depths it leaves, line for
// line. An inside shape has a membership test and no distance, so a ray
// within its region samples points at most BRUTE_STEP footprints apart
// (march.wgsl), and a hit on it takes its normal and occlusion from the
// neighbouring pixels' hits: the compute entry point `brute_pass` marches
// every sample of the pass first into `brute_depths`, and `render` shades
// them.
//
// Follows render.wgsl, and is part of the module only where the scene
// has inside shapes. The module defines before it SCREEN_NORMALS (0:
// central differences, 1: least squares).

// Where a pixel's brute-force steps start on its sample j, in [0, 1) of a
// step: an offset of its own, advanced by the golden ratio's fraction from
// one sample to the next, so successive passes spread their lattices
// evenly over the step.
fn march_brute_phase(pixel: uint, j: uint) -> real {
    let u = march_jitter(pixel, 0u, 2u) + 0.61803398874989485 * real(j);
    return u - floor(u);
}

// The brute-force pass: marches sample s of this pass at every rendered
// pixel and leaves its depth (on a miss, -1 less the angle of its nearest
// miss, which the glow reads) and evaluations for `render` to shade.
@compute @workgroup_size(8, 8)
fn brute_pass(@builtin(global_invocation_id) id: vec3<uint>) {
    if (id.x >= frame.width || id.y >= frame.height) {
        return;
    }
    let cam = march_load_camera();
    let x = int(id.x);
    let y = int(id.y);
    let pixel = id.y * frame.width + id.x;
    let first = uint(max(frame.pass_index, 0) * PER_PASS);
    for (var s = 0; s < PER_PASS; s++) {
        let j = first + uint(s);
        let sample = march_sample_ray(cam, x, y, pixel, j, s);
        march_phase = march_brute_phase(pixel, j);
        let m = march_ray(sample.ray.ro, sample.ray.rd, 0.0, cam.footprint, 1.0);
        var depth = -1.0 - m.closest;
        if (m.hit) {
            depth = m.t;
        }
        brute_depths[march_stored_at(x, y, s)] = real2(depth, real(m.steps));
    }
}

// Where sample s of rendered pixel (x, y) lies in `brute_depths`.
fn march_stored_at(x: int, y: int, s: int) -> uint {
    return uint((s * int(frame.height) + y) * int(frame.width) + x);
}

// The march of sample s at (x, y), from the depths the pass left.
fn march_stored(x: int, y: int, s: int) -> MarchResult {
    let stored = brute_depths[march_stored_at(x, y, s)];
    var m: MarchResult;
    m.hit = stored.x >= 0.0;
    m.t = select(0.0, stored.x, m.hit);
    m.closest = select(-1.0 - stored.x, 0.0, m.hit);
    m.steps = int(stored.y);
    for (var k = 0; k < GLOW_NODES; k++) {
        m.glow_closest[k] = 1.0;
    }
    return m;
}

// The hit point of sample s (sample j of the image) at rendered pixel
// (x, y), from the stored depths: w 0 where the pixel is outside the image
// or its ray missed.
fn march_stored_point(cam: MarchCamera, x: int, y: int, s: int, j: uint) -> real4 {
    if (x < 0 || y < 0 || x >= int(frame.width) || y >= int(frame.height)) {
        return real4(0.0);
    }
    let t = brute_depths[march_stored_at(x, y, s)].x;
    if (t < 0.0) {
        return real4(0.0);
    }
    let sample = march_sample_ray(cam, x, y, uint(y) * frame.width + uint(x), j, s);
    return real4(sample.ray.ro + sample.ray.rd * t, 1.0);
}

// Neighbours whose hit points lie within this many brute-force steps (and
// at least this many footprints) of a pixel's, per pixel between them, are
// on its surface.
const MARCH_SCREEN_REACH: real = 6.0;
// The least-squares fit takes the neighbours up to this many pixels away.
const MARCH_FIT_RADIUS: int = 1;
const MARCH_FIT_SIDE: int = 2 * MARCH_FIT_RADIUS + 1;

// The hit of sample s at the pixel (dx, dy) away from (x, y), if it lies
// on the same surface as p: w 0 where it does not.
fn march_neighbour(cam: MarchCamera, x: int, y: int, dx: int, dy: int, s: int, j: uint,
                   p: real3, reach: real) -> real4 {
    let q = march_stored_point(cam, x + dx, y + dy, s, j);
    if (q.w > 0.0 && length(q.xyz - p) <= reach * real(max(abs(dx), abs(dy)))) {
        return q;
    }
    return real4(p, 0.0);
}

// The normal at p, the hit of sample s at pixel (x, y) along rd, from its
// neighbours' hits on the same surface (render.cl's march_screen_normal):
// the cross product of the central differences across the pixel,
// one-sided where a neighbour is elsewhere; with SCREEN_NORMALS 1,
// Englund's least-squares plane through the hits up to MARCH_FIT_RADIUS
// pixels away, where they span one. Faces the viewer; -rd where no plane
// can be found.
fn march_screen_normal(cam: MarchCamera, x: int, y: int, s: int, j: uint, p: real3, rd: real3,
                       footprint: real) -> real3 {
    let reach = MARCH_SCREEN_REACH * max(BRUTE_STEP, 1.0) * footprint;
    let left = march_neighbour(cam, x, y, -1, 0, s, j, p, reach);
    let right = march_neighbour(cam, x, y, 1, 0, s, j, p, reach);
    let up = march_neighbour(cam, x, y, 0, -1, s, j, p, reach);
    let down = march_neighbour(cam, x, y, 0, 1, s, j, p, reach);
    let across = left.w > 0.0 || right.w > 0.0;
    let along = up.w > 0.0 || down.w > 0.0;
    // Central differences, or one-sided ones (a missing neighbour is p).
    var n = real3(0.0);
    if (across && along) {
        n = cross(right.xyz - left.xyz, down.xyz - up.xyz);
    }
    if (SCREEN_NORMALS == 1) {
        var pts: array<real4, MARCH_FIT_SIDE * MARCH_FIT_SIDE>;
        var sum = real3(0.0);
        var count = 0.0;
        for (var k = 0; k < MARCH_FIT_SIDE * MARCH_FIT_SIDE; k++) {
            let dx = k % MARCH_FIT_SIDE - MARCH_FIT_RADIUS;
            let dy = k / MARCH_FIT_SIDE - MARCH_FIT_RADIUS;
            if (dx == 0 && dy == 0) {
                pts[k] = real4(p, 1.0);
            } else {
                pts[k] = march_neighbour(cam, x, y, dx, dy, s, j, p, reach);
            }
            if (pts[k].w > 0.0) {
                sum += pts[k].xyz;
                count += 1.0;
            }
        }
        let mean = sum / count;
        var suu = 0.0;
        var suv = 0.0;
        var svv = 0.0;
        var suw = 0.0;
        var svw = 0.0;
        for (var k = 0; k < MARCH_FIT_SIDE * MARCH_FIT_SIDE; k++) {
            if (pts[k].w > 0.0) {
                let d = pts[k].xyz - mean;
                let u = dot(d, cam.right);
                let v = dot(d, cam.up);
                let w = dot(d, cam.forward);
                suu += u * u;
                suv += u * v;
                svv += v * v;
                suw += u * w;
                svw += v * w;
            }
        }
        let det = suu * svv - suv * suv;
        if (count >= 3.0 && det > 1e-3 * suu * svv) {
            // w = a u + b v: the surface's gradient is (-a, -b, 1).
            let a = (suw * svv - svw * suv) / det;
            let b = (svw * suu - suw * suv) / det;
            n = a * cam.right + b * cam.up - cam.forward;
        }
    }
    let len = length(n);
    if (!(len > REAL_TINY)) {
        return -rd;
    }
    n /= len;
    if (dot(n, rd) > 0.0) {
        return -n;
    }
    return n;
}

const MARCH_SSAO_SAMPLES: int = 16;

// Screen-space ambient occlusion at p, the hit of sample s at pixel
// (x, y), with normal n (render.cl's march_screen_occlusion): neighbours
// on a golden-angle spiral out to the pixels the occlusion's reach covers,
// each occluding by how far above p's tangent plane its hit lies, fading
// to nothing at twice the reach. 1 on an open face, towards 0 in a crease.
fn march_screen_occlusion(cam: MarchCamera, x: int, y: int, s: int, j: uint, p: real3,
                          n: real3, footprint: real, view_height: real) -> real {
    if (!ENABLE_AO) {
        return 1.0;
    }
    let reach = min(AO_DISTANCE, AO_VIEW_FRACTION * view_height);
    let radius = clamp(reach / footprint, 2.0, 32.0);
    let turn = 6.28318530717958648 * march_jitter(uint(y) * frame.width + uint(x), j, 3u);
    var hidden = 0.0;
    for (var k = 0; k < MARCH_SSAO_SAMPLES; k++) {
        let angle = turn + 2.39996322972865332 * real(k);
        let r = radius * sqrt((real(k) + 0.5) / real(MARCH_SSAO_SAMPLES));
        let qx = x + int(round(r * cos(angle)));
        let qy = y + int(round(r * sin(angle)));
        let q = march_stored_point(cam, qx, qy, s, j);
        if (q.w > 0.0) {
            let v = q.xyz - p;
            let d = length(v);
            if (d > REAL_TINY) {
                let rise = max(dot(n, v) / d - 0.1, 0.0);
                hidden += rise * clamp(1.0 - d / (2.0 * reach), 0.0, 1.0);
            }
        }
    }
    return clamp(1.0 - 2.0 * hidden / real(MARCH_SSAO_SAMPLES), 0.0, 1.0);
}
