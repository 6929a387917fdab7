// The coarse pass in WGSL: render.cl's cone_starts, line for line. For
// each tile of CONE_TILE x CONE_TILE rendered pixels, a cone around the ray
// through the tile's centre, wide enough to hold every ray through the
// tile (and, with a lens, every ray through the lens), is sphere-traced
// like a ray until it could reach the drawn surface or the glow's margin;
// each ray of the tile then starts where the cone stopped rather than at
// the camera. The surface is the same; the march finds it in fewer steps.
//
// Follows render.wgsl, and is part of the module only where the quality
// asks for the coarse pass and the scene has no inside shapes (which a
// cone cannot see). The module defines before it CONE_TILE.

const CONE_STEPS: int = 64; // most evaluations of a tile's cone

// The tiles' columns across the rendered image.
fn cone_columns() -> uint {
    return (frame.width + CONE_TILE - 1u) / CONE_TILE;
}

// Where the rays of rendered pixel (x, y) start: its tile's distance.
fn cone_start(x: int, y: int) -> real {
    return cone_starts[(uint(y) / CONE_TILE) * cone_columns() + uint(x) / CONE_TILE];
}

// The coarse pass: one invocation per tile (render.cl's cone_starts).
@compute @workgroup_size(8, 8)
fn cone_pass(@builtin(global_invocation_id) id: vec3<uint>) {
    let columns = cone_columns();
    let rows = (frame.height + CONE_TILE - 1u) / CONE_TILE;
    if (id.x >= columns || id.y >= rows) {
        return;
    }
    let cam = march_load_camera();
    let x0 = real(id.x * CONE_TILE) * cam.pixel_scale;
    let y0 = real(id.y * CONE_TILE) * cam.pixel_scale;
    let x1 = real(min((id.x + 1u) * CONE_TILE, frame.width)) * cam.pixel_scale;
    let y1 = real(min((id.y + 1u) * CONE_TILE, frame.height)) * cam.pixel_scale;
    let axis = march_camera_ray(cam, 0.5 * (x0 + x1), 0.5 * (y0 + y1));
    var rho0 = 0.0;
    var cos_theta = 1.0;
    for (var i = 0; i < 4; i++) {
        let corner = march_camera_ray(cam, select(x0, x1, (i & 1) != 0),
                                      select(y0, y1, (i & 2) != 0));
        rho0 = max(rho0, length(corner.ro - axis.ro));
        cos_theta = min(cos_theta, dot(corner.rd, axis.rd));
    }
    // A margin for the rounding of the corner rays.
    rho0 *= 1.01;
    cos_theta = clamp(cos_theta - 1e-6, 0.1, 1.0);
    var tan_theta = sqrt(1.0 - cos_theta * cos_theta) / cos_theta;
    // A lens of radius a moves each ray off its pinhole ray by at most
    // a + tau a / focus at tau along the axis.
    if (cam.aperture > 0.0) {
        rho0 += cam.aperture;
        tan_theta += cam.aperture / cam.focus;
    }
    let sec_theta = sqrt(1.0 + tan_theta * tan_theta);
    let widen = 1.0 + tan_theta + march_glow_slope() * sec_theta;
    var t = 0.0;
    for (var i = 0; i < CONE_STEPS; i++) {
        let d = DE(axis.ro + axis.rd * t);
        // The surface lies DETAIL footprints out, measured along a ray at
        // most (t + d) sec(theta) long here (twice that, for margin).
        let reach = d - DETAIL * march_footprint(cam.footprint, 2.0 * (t + abs(d)) * sec_theta);
        let next = (reach + t - rho0) / widen;
        if (!(next > t)) {
            break;
        }
        t = next;
        if (t > MAX_DISTANCE) {
            break;
        }
    }
    // Rounded down, so no ray starts beyond it.
    cone_starts[id.y * columns + id.x] = t * 0.999;
}
