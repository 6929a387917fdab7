//! The frame loop: tiles launched and settled, the coarse cone pass,
//! progressive and adaptive passes, multi-device shares and timing.

use super::*;

impl Renderer {
    /// Renders a frame with the partners: each device its share of the
    /// tiles, at once, then the partners' tiles copied into this one's.
    pub(super) fn render_shared(&mut self, width: u32, height: u32) -> Result<RgbaImage> {
        let n = self.partners.len() + 1;
        let mut partners = std::mem::take(&mut self.partners);
        let (mine, theirs) = std::thread::scope(|s| {
            let handles: Vec<_> = partners
                .iter_mut()
                .enumerate()
                .map(|(i, p)| s.spawn(move || p.render_share(width, height, (i + 1, n))))
                .collect();
            let mine = self.render_share(width, height, (0, n));
            let theirs: Vec<Result<Rendered>> = handles
                .into_iter()
                .map(|h| h.join().expect("a device's thread does not panic"))
                .collect();
            (mine, theirs)
        });
        self.partners = partners;
        let mut low = mine?;
        let theirs = theirs.into_iter().collect::<Result<Vec<_>>>()?;
        let (lw, lh) = low.image.dimensions();
        let span = |y: u32, x: u32, w: u32| {
            let start = (y * lw + x) as usize;
            start..start + w as usize
        };
        for (i, tile) in dispatch::tiles(lw, lh, self.options.tile_size).enumerate() {
            let Some(from) = (i % n).checked_sub(1).map(|p| &theirs[p]) else {
                continue;
            };
            for y in tile.y..tile.y + tile.height {
                let pixels = span(y, tile.x, tile.width);
                let bytes = 4 * pixels.start..4 * pixels.end;
                let (dst, src): (&mut [u8], &[u8]) = (&mut low.image, &from.image);
                dst[bytes.clone()].copy_from_slice(&src[bytes]);
                if let (Some(dst), Some(src)) = (&mut low.depth, &from.depth) {
                    dst[pixels.clone()].copy_from_slice(&src[pixels]);
                }
            }
        }
        Ok(low.scaled(width, height, self.scale()))
    }

    /// Renders this renderer's `share` of the tiles (the rest of the image
    /// is left as it was), at the rendered resolution.
    pub(super) fn render_share(
        &mut self,
        width: u32,
        height: u32,
        share: (usize, usize),
    ) -> Result<Rendered> {
        self.share = share;
        let image = self.render_low(width, height);
        self.share = (0, 1);
        image
    }

    /// Image pixels per rendered pixel along each axis
    /// ([`Quality::resolution_scale`]).
    pub(super) fn scale(&self) -> u32 {
        self.options.quality.resolution_scale.max(1)
    }

    /// Renders a `width` × `height` image.
    ///
    /// # Errors
    /// [`Error::Resolution`] for a zero side, a side above 32768, an image
    /// whose buffers the device cannot hold, or one whose host memory (the
    /// copies read back, and a CPU device's buffers) exceeds what the
    /// machine has available (`MemAvailable`, and the process's cgroup
    /// limit, on Linux) — each with the numbers; [`Error::Precision`] for a
    /// camera or lights the program's precision cannot compute with at this
    /// size; [`Error::Cancelled`] or [`Error::Deadline`] when
    /// [`RenderOptions::cancel`] or [`RenderOptions::deadline`] stops the
    /// frame between tiles; [`Error::OpenCl`] if the device fails.
    pub fn render(&mut self, width: u32, height: u32) -> Result<RgbaImage> {
        if self.partners.is_empty() {
            self.render_alone(width, height)
        } else {
            self.render_shared(width, height)
        }
    }

    /// Renders one more progressive pass of a `width` × `height` image and
    /// returns the mean of every pass so far.
    ///
    /// The first pass is the frame [`Renderer::render`] draws. Each later
    /// pass adds [`Quality::supersampling`]² new samples to every pixel,
    /// each at its own point in the pixel and on the lens
    /// ([`Camera::aperture`]), and the image converges on the mean over
    /// the pixel and the lens: edges smooth out and depth of field
    /// becomes a soft blur. The sums are kept on the device, so a pass
    /// costs one frame's samples whatever the count.
    ///
    /// Changing the camera, lights, a parameter, the quality, the effects
    /// or the size starts again from the first pass; so does
    /// [`Renderer::restart_progressive`]. Past
    /// [`Renderer::MAX_PROGRESSIVE_SAMPLES`] samples per pixel the image
    /// has converged, and a further call renders no more passes but
    /// returns it again.
    ///
    /// ```no_run
    /// use fractal_sdf::prelude::*;
    /// use fractal_sdf::render::Renderer;
    ///
    /// let camera = Camera::look_at(dvec3(0.0, 0.5, 3.0), DVec3::ZERO).lens(0.08);
    /// let scene = Scene::new(mandelbulb(8.0)).with_camera(camera);
    /// let mut renderer = Renderer::new(&scene, Quality::preview())?;
    /// let mut image = renderer.render_progressive(320, 240)?;
    /// while renderer.progressive_passes() < 16 {
    ///     image = renderer.render_progressive(320, 240)?;
    /// }
    /// # let _ = image;
    /// # Ok::<(), fractal_sdf::Error>(())
    /// ```
    ///
    /// # Errors
    /// As [`Renderer::render`]; after a failed pass the next call starts
    /// again from the first.
    pub fn render_progressive(&mut self, width: u32, height: u32) -> Result<RgbaImage> {
        self.progressive(
            width,
            height,
            Outputs::Image,
            |r| r.render(width, height),
            |image| Converged::Image(image.clone()),
            |kept| match kept {
                Converged::Image(image) => Some(image.clone()),
                Converged::Frame(_) => None,
            },
        )
    }

    /// A progressive pass that renders with `render`, launching `outputs`.
    /// Passes continue only those that wrote the same outputs (the image
    /// passes run on every device, the others on this renderer's own).
    /// Once the passes are all done, `keep` holds the result and `reuse`
    /// gives it again.
    fn progressive<T>(
        &mut self,
        width: u32,
        height: u32,
        outputs: Outputs,
        render: impl FnOnce(&mut Self) -> Result<T>,
        keep: impl FnOnce(&T) -> Converged,
        reuse: impl FnOnce(&Converged) -> Option<T>,
    ) -> Result<T> {
        let last = self.most_passes();
        let (lw, lh) = self.rendered_size(width, height);
        // Sums lost with buffers made anew (for another size, or more
        // outputs) start again.
        let kept = self.targets.fits(lw, lh, outputs, true);
        let done = match &self.progress {
            Some(p) if (p.width, p.height, p.outputs) == (width, height, outputs) && kept => {
                if let Some(result) = p.converged.as_ref().and_then(reuse) {
                    return Ok(result);
                }
                p.passes
            }
            _ => 0,
        };
        self.progress = None;
        self.set_pass(i32::try_from(done).expect("passes are at most 4096"));
        let result = render(self);
        self.set_pass(-1);
        let result = result?;
        let passes = done + 1;
        self.progress = Some(Progress {
            width,
            height,
            passes,
            outputs,
            converged: (passes == last).then(|| keep(&result)),
        });
        Ok(result)
    }

    /// Renders one image as the mean of a progressive pass at each of
    /// `moments`, calling `set(self, moment)` before each pass to move the
    /// camera, the lights or the parameters there: a frame blurred over
    /// the changes, as a shutter open while they happen blurs it (see
    /// [`crate::sequence::MotionBlur`]). Each pass takes new samples in the
    /// pixel, on the lens and along paths, so the moments share no noise.
    /// It leaves the progressive passes to start again.
    ///
    /// # Errors
    /// [`Error::Quality`] for more moments than
    /// [`Renderer::MAX_PROGRESSIVE_SAMPLES`] samples a pixel allow, or
    /// none; else the first error of `set` or of a pass.
    pub fn render_over_time<T>(
        &mut self,
        width: u32,
        height: u32,
        moments: &[T],
        set: impl FnMut(&mut Self, &T) -> Result<()>,
    ) -> Result<RgbaImage> {
        self.over_time(moments, set, |r| r.render(width, height))
    }

    /// As [`Renderer::render_over_time`], with every output of
    /// [`Renderer::render_layers`]: the linear colour and coverage the
    /// mean over the moments, the other outputs the first moment's.
    ///
    /// # Errors
    /// As [`Renderer::render_over_time`].
    pub fn render_layers_over_time<T>(
        &mut self,
        width: u32,
        height: u32,
        moments: &[T],
        set: impl FnMut(&mut Self, &T) -> Result<()>,
    ) -> Result<Frame> {
        self.over_time(moments, set, |r| r.render_layers(width, height))
    }

    /// A progressive pass of `render` at each of `moments`, `set` before
    /// each: the last pass's result, the mean of them all.
    fn over_time<T, R>(
        &mut self,
        moments: &[T],
        mut set: impl FnMut(&mut Self, &T) -> Result<()>,
        mut render: impl FnMut(&mut Self) -> Result<R>,
    ) -> Result<R> {
        let count = u32::try_from(moments.len()).unwrap_or(u32::MAX);
        if count == 0 || count > self.most_passes() {
            return Err(Error::Quality {
                setting: "moments",
                value: f64::from(count),
                expected: format!("1 to {} for the quality's samples", self.most_passes()),
            });
        }
        // The accumulation is about to be overwritten: no earlier passes
        // continue, even after an error.
        self.progress = None;
        let mut last = None;
        for (pass, moment) in (0i32..).zip(moments) {
            let done = set(self, moment).and_then(|()| {
                self.set_pass(pass);
                render(self)
            });
            self.set_pass(-1);
            last = Some(done?);
        }
        self.progress = None;
        Ok(last.expect("at least one moment"))
    }

    /// The progressive passes in the last image of
    /// [`Renderer::render_progressive`]: 0 before the first, or after
    /// anything that restarts it.
    #[must_use]
    pub fn progressive_passes(&self) -> u32 {
        self.progress.as_ref().map_or(0, |p| p.passes)
    }

    /// Makes the next [`Renderer::render_progressive`] start from its
    /// first pass.
    pub fn restart_progressive(&mut self) {
        self.progress = None;
    }

    /// Renders a `width` × `height` image with adaptive supersampling: a
    /// first pass with its outputs everywhere, then `passes - 1` further
    /// progressive passes only at the pixels that differ from a neighbour
    /// by more than `thresholds` ([`adaptive::edges`]: a silhouette, a
    /// crease, a depth step, a colour edge such as a shadow's). A refined
    /// pixel is the mean of every pass's samples, exactly the pixel
    /// [`Renderer::render_progressive`] gives after as many passes; the
    /// rest keep their first sample. It renders on the first device alone,
    /// as [`Renderer::render_with_aovs`] does, and starts the progressive
    /// passes again.
    ///
    /// ```no_run
    /// use fractal_sdf::prelude::*;
    /// use fractal_sdf::render::{EdgeThresholds, Renderer};
    ///
    /// let mut renderer = Renderer::new(&fractal_sdf::gallery::csg(), Quality::production())?;
    /// let frame = renderer.render_adaptive(640, 480, 16, &EdgeThresholds::default())?;
    /// println!("{:.0}% of the pixels refined", 100.0 * frame.refined_fraction());
    /// # Ok::<(), fractal_sdf::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::Quality`] for `passes` of 0 or past
    /// [`Renderer::MAX_PROGRESSIVE_SAMPLES`] samples per pixel; else as
    /// [`Renderer::render`].
    pub fn render_adaptive(
        &mut self,
        width: u32,
        height: u32,
        passes: u32,
        thresholds: &EdgeThresholds,
    ) -> Result<AdaptiveFrame> {
        let most = self.most_passes();
        if passes == 0 || passes > most {
            return Err(Error::Quality {
                setting: "adaptive passes",
                value: f64::from(passes),
                expected: format!("in 1..={most} at this supersampling"),
            });
        }
        self.progress = None;
        let frame = self.refine_adaptively(width, height, passes, thresholds);
        self.pass = -1;
        self.refine_only = false;
        frame
    }

    pub(super) fn refine_adaptively(
        &mut self,
        width: u32,
        height: u32,
        passes: u32,
        thresholds: &EdgeThresholds,
    ) -> Result<AdaptiveFrame> {
        self.pass = 0;
        let first = self.render_with_aovs(width, height)?;
        let marked = adaptive::edges(&first, thresholds);
        // The rendered pixels: one for every `scale` × `scale` of the
        // image, refined if any of them is marked.
        let scale = self.scale();
        let (lw, lh) = self.rendered_size(width, height);
        let mut refined = vec![false; lw as usize * lh as usize];
        for (i, _) in marked.iter().enumerate().filter(|(_, m)| **m) {
            let (x, y) = (i as u32 % width / scale, i as u32 / width / scale);
            refined[(y * lw + x) as usize] = true;
        }
        let bytes: Vec<u8> = refined.iter().map(|&r| u8::from(r)).collect();
        self.targets.refine.write(&bytes).enq().map_err(opencl)?;
        self.refine_only = true;
        let mut image = first.image.clone();
        for pass in 1..passes {
            self.pass = i32::try_from(pass).expect("passes are at most 4096");
            image = self.render_low(width, height)?.scaled(width, height, scale);
        }
        Ok(AdaptiveFrame {
            image,
            first,
            refined,
            passes,
        })
    }

    /// The most progressive passes at the quality's supersampling: as many
    /// as make [`Renderer::MAX_PROGRESSIVE_SAMPLES`], one at least.
    pub(super) fn most_passes(&self) -> u32 {
        let per_pass = self.options.quality.supersampling.max(1).pow(2);
        (Self::MAX_PROGRESSIVE_SAMPLES / per_pass).max(1)
    }

    /// Sets the kernel's `pass` here and on the partners.
    pub(super) fn set_pass(&mut self, pass: i32) {
        self.pass = pass;
        for p in &mut self.partners {
            p.set_pass(pass);
        }
    }

    /// Renders the image on this renderer's own device.
    pub(super) fn render_alone(&mut self, width: u32, height: u32) -> Result<RgbaImage> {
        let start = Instant::now();
        let low = self.render_low(width, height)?;
        let image = low.scaled(width, height, self.scale());
        if let Some(t) = &mut self.timing {
            t.total = start.elapsed();
        }
        Ok(image)
    }

    /// Renders this renderer's share of the tiles on its own device, at the
    /// rendered resolution (with depth, to scale it up by, when that is
    /// smaller than the image's).
    pub(super) fn render_low(&mut self, width: u32, height: u32) -> Result<Rendered> {
        let start = Instant::now();
        let scaled = self.scale() > 1;
        let outputs = if scaled {
            Outputs::Aovs
        } else {
            Outputs::Image
        };
        let kernel = self.run(width, height, outputs)?;
        let read = Instant::now();
        let (lw, lh) = self.rendered_size(width, height);
        let mut rgba = host_vec::<u8>(lw, lh, 4)?;
        self.targets.rgba.read(&mut rgba).enq().map_err(opencl)?;
        let depth = if scaled {
            let mut depth = host_vec::<f32>(lw, lh, 1)?;
            self.targets.depth.read(&mut depth).enq().map_err(opencl)?;
            Some(depth)
        } else {
            None
        };
        self.record_timing(start, read, kernel);
        Ok(Rendered {
            image: RgbaImage::from_raw(lw, lh, rgba).expect("buffer has width * height * 4 bytes"),
            depth,
        })
    }

    /// The size the kernel renders for a `width` × `height` image: smaller
    /// by [`Quality::resolution_scale`], rounded up.
    pub(super) fn rendered_size(&self, width: u32, height: u32) -> (u32, u32) {
        let k = self.scale();
        (width.div_ceil(k), height.div_ceil(k))
    }

    /// Renders a `width` × `height` image with depth, hit mask, normal and
    /// cost outputs (see [`Frame`]).
    ///
    /// # Errors
    /// As [`Renderer::render`].
    pub fn render_with_aovs(&mut self, width: u32, height: u32) -> Result<Frame> {
        self.render_outputs(width, height, Outputs::Aovs)
    }

    /// Renders a `width` × `height` image with every output: those of
    /// [`Renderer::render_with_aovs`] and the shading [`Layers`] (the
    /// exposed linear colour and coverage, world position, albedo,
    /// occlusion, shadow and orbit-trap value), for writing an OpenEXR
    /// file or compositing.
    ///
    /// ```no_run
    /// use fractal_sdf::prelude::*;
    /// use fractal_sdf::render::Renderer;
    ///
    /// let scene = Scene::new(sphere(1.0));
    /// let mut renderer = Renderer::new(&scene, Quality::preview())?;
    /// let frame = renderer.render_layers(64, 48)?;
    /// let layers = frame.layers.as_ref().expect("rendered with layers");
    /// let centre = frame.index(32, 24);
    /// assert!(frame.hit[centre] && layers.linear[centre][3] == 1.0);
    /// # Ok::<(), fractal_sdf::Error>(())
    /// ```
    ///
    /// With [`Quality::resolution_scale`] above 1, the colour is blended
    /// up as the image is, and the other layers come from the nearest
    /// rendered pixel, as the depth does. A renderer with partner devices
    /// renders layers on its own device alone.
    ///
    /// # Errors
    /// As [`Renderer::render`].
    pub fn render_layers(&mut self, width: u32, height: u32) -> Result<Frame> {
        self.render_outputs(width, height, Outputs::Layers)
    }

    /// One more progressive pass, as [`Renderer::render_progressive`]
    /// renders, with every output of [`Renderer::render_layers`]: the
    /// linear colour and coverage are the mean of every pass so far; the
    /// other outputs are the first pass's. Like `render_layers`, it runs on
    /// this renderer's own device, not its partners'; its passes and
    /// `render_progressive`'s do not continue each other.
    ///
    /// # Errors
    /// As [`Renderer::render_progressive`].
    pub fn render_progressive_layers(&mut self, width: u32, height: u32) -> Result<Frame> {
        self.progressive(
            width,
            height,
            Outputs::Layers,
            |r| r.render_layers(width, height),
            |frame| Converged::Frame(Box::new(frame.clone())),
            |kept| match kept {
                Converged::Frame(frame) => Some((**frame).clone()),
                Converged::Image(_) => None,
            },
        )
    }

    /// Launches the frame and reads `outputs` back.
    fn render_outputs(&mut self, width: u32, height: u32, outputs: Outputs) -> Result<Frame> {
        let start = Instant::now();
        let kernel = self.run(width, height, outputs)?;
        let read = Instant::now();
        let frame = self.read_frame(width, height, outputs)?;
        self.record_timing(start, read, kernel);
        Ok(frame)
    }

    /// Reads the last launch's `outputs` (at least the AOVs) back, scaled
    /// up to `width` × `height`.
    fn read_frame(&mut self, width: u32, height: u32, outputs: Outputs) -> Result<Frame> {
        let (image_w, image_h, scale) = (width, height, self.scale());
        let (width, height) = self.rendered_size(width, height);
        let t = &self.targets;
        let mut rgba = host_vec::<u8>(width, height, 4)?;
        let mut depth = host_vec::<f32>(width, height, 1)?;
        let mut hit = host_vec::<u8>(width, height, 1)?;
        let mut normals = host_vec::<f32>(width, height, 3)?;
        let mut steps = host_vec::<u32>(width, height, 1)?;
        let mut evaluations = host_vec::<u32>(width, height, 1)?;
        t.rgba.read(&mut rgba).enq().map_err(opencl)?;
        t.depth.read(&mut depth).enq().map_err(opencl)?;
        t.hit.read(&mut hit).enq().map_err(opencl)?;
        t.normals.read(&mut normals).enq().map_err(opencl)?;
        t.steps.read(&mut steps).enq().map_err(opencl)?;
        t.evaluations.read(&mut evaluations).enq().map_err(opencl)?;
        let layers = if outputs >= Outputs::Layers {
            let mut linear = host_vec::<f32>(width, height, 4)?;
            let mut flat = host_vec::<f32>(width, height, layer::STRIDE)?;
            t.linear.read(&mut linear).enq().map_err(opencl)?;
            t.layers.read(&mut flat).enq().map_err(opencl)?;
            Some(layers_of(&linear, &flat, &hit, self.source.origin))
        } else {
            None
        };
        let starts = self.starts(width, height)?;
        let frame = Frame {
            start: starts,
            image: RgbaImage::from_raw(width, height, rgba)
                .expect("buffer has width * height * 4 bytes"),
            depth,
            hit: hit.into_iter().map(|h| h != 0).collect(),
            normal: normals
                .chunks_exact(3)
                .map(|n| [n[0], n[1], n[2]])
                .collect(),
            steps,
            evaluations,
            layers,
        };
        Ok(if scale > 1 {
            upscale::frame(&frame, image_w, image_h, scale)
        } else {
            frame
        })
    }

    /// Fills the frame's object and material ids ([`Layers::object`],
    /// [`Layers::material`]): for each hit, the shape and the material
    /// node nearest its position, as the CPU reference
    /// ([`crate::cpu::Evaluator`]) finds them with the renderer's current
    /// parameters, numbered as [`Ir::objects`](crate::ir::Ir::objects)
    /// and [`Ir::materials`](crate::ir::Ir::materials) list them. It costs
    /// one evaluation of the scene on the host per hit (pruned, and
    /// through a hierarchy over large unions, as the kernels evaluate),
    /// shared among the host's threads, so only the frames that need ids
    /// pay for it: a 640×480 frame of 100,000 spheres takes about 0.6 s.
    ///
    /// # Errors
    /// [`Error::Invalid`] for a frame without shading layers (render it
    /// with [`Renderer::render_layers`]).
    pub fn identify(&self, frame: &mut Frame) -> Result<()> {
        let Some(layers) = frame.layers.as_mut() else {
            return Err(Error::Invalid {
                what: "frame",
                reason: "object ids need the shading layers: render it with \
                         Renderer::render_layers"
                    .into(),
            });
        };
        let ir = self.scene.ir();
        let number = |list: Vec<crate::ir::NodeId>| {
            let mut of = vec![0u32; ir.nodes().len()];
            for (k, id) in list.into_iter().enumerate() {
                of[id.index()] = u32::try_from(k + 1).expect("fewer than 2^32 nodes");
            }
            of
        };
        let (objects, materials) = (number(ir.objects()), number(ir.materials()));
        let eval =
            crate::cpu::Evaluator::from_compiled(&self.scene).with_values(self.values.clone());
        let n = layers.position.len();
        let threads = std::thread::available_parallelism().map_or(1, usize::from);
        let chunk = n.div_ceil(threads).max(1);
        let mut object = vec![0u32; n];
        let mut material = vec![0u32; n];
        std::thread::scope(|scope| {
            for (((p, h), o), m) in layers
                .position
                .chunks(chunk)
                .zip(frame.hit.chunks(chunk))
                .zip(object.chunks_mut(chunk))
                .zip(material.chunks_mut(chunk))
            {
                let (eval, objects, materials) = (&eval, &objects, &materials);
                scope.spawn(move || {
                    for (((p, &h), o), m) in p.iter().zip(h).zip(o).zip(m) {
                        if h {
                            let at = DVec3::new(p[0].into(), p[1].into(), p[2].into());
                            let sample = eval.sample::<f64>(at.into());
                            *o = sample.object.map_or(0, |id| objects[id.index()]);
                            *m = sample.material_node.map_or(0, |id| materials[id.index()]);
                        }
                    }
                });
            }
        });
        layers.object = object;
        layers.material = material;
        Ok(())
    }

    pub(super) fn record_timing(
        &mut self,
        start: Instant,
        read: Instant,
        kernel: (Duration, bool),
    ) {
        let end = Instant::now();
        self.timing = Some(FrameTiming {
            kernel: kernel.0,
            readback: end - read,
            total: end - start,
            profiled: kernel.1,
        });
    }

    /// Each rendered pixel's start distance: its tile's, read back from the
    /// coarse pass, or 0 without one.
    pub(super) fn starts(&self, width: u32, height: u32) -> Result<Vec<f32>> {
        let side = self.source.cone_tile;
        let mut out = host_vec::<f32>(width, height, 1)?;
        if side == 0 {
            return Ok(out);
        }
        let columns = width.div_ceil(side);
        let mut tiles = vec![0.0f32; cone_tiles(width, height, side)];
        self.targets.starts.read(&mut tiles).enq().map_err(opencl)?;
        for y in 0..height {
            for x in 0..width {
                out[(y * width + x) as usize] = tiles[((y / side) * columns + x / side) as usize];
            }
        }
        Ok(out)
    }

    /// Launches the coarse pass over a `width` × `height` rendering: the
    /// start distance of every tile's rays (see `cone_starts` in `kernels/render.cl`).
    pub(super) fn coarse_pass(&self, cone: &Kernel, width: u32, height: u32) -> Result<Event> {
        let side = self.source.cone_tile;
        let set = |a: ConeArg, v: i32| cone.set_arg(a.index(), v).map_err(opencl);
        #[allow(clippy::cast_possible_wrap)] // sizes are at most MAX_IMAGE_SIDE
        {
            set(ConeArg::Width, width as i32)?;
            set(ConeArg::Height, height as i32)?;
        }
        self.inputs.params.set_arg(cone, ConeArg::Params.index())?;
        self.inputs.camera.set_arg(cone, ConeArg::Camera.index())?;
        cone.set_arg(ConeArg::Starts.index(), &self.targets.starts)
            .map_err(opencl)?;
        let global = (
            width.div_ceil(side).next_multiple_of(8) as usize,
            height.div_ceil(side).next_multiple_of(8) as usize,
        );
        let mut event = Event::empty();
        // SAFETY: every buffer argument is alive in `self`, and the kernel
        // bounds-checks every work item against the grid of tiles.
        unsafe {
            cone.cmd()
                .global_work_size(global)
                .enew(&mut event)
                .enq()
                .map_err(opencl)?;
        }
        Ok(event)
    }

    /// Waits for `event` (a tile launch; the queue is in order, so every
    /// command before it too). Under a deadline the wait is a watchdog: a
    /// launch still running at twice the deadline (the frame's time, then
    /// as long again for the launches in flight) is given up, and the
    /// [`Error::Deadline`] to fail the frame with is returned: the caller
    /// marks the renderer abandoned. `(tiles, total)`: the tiles launched
    /// so far and the frame's, for the error.
    pub(super) fn settle(
        &self,
        event: Option<&Event>,
        launched: Instant,
        (tiles, total): (usize, usize),
    ) -> Result<Option<Error>> {
        let Some(event) = event else { return Ok(None) };
        let Some(deadline) = self.options.deadline else {
            return event.wait_for().map(|()| None).map_err(opencl);
        };
        let mut pause = Duration::from_micros(50);
        while !event.is_complete().map_err(opencl)? {
            if launched.elapsed() >= deadline.saturating_mul(2) {
                return Ok(Some(Error::Deadline {
                    deadline,
                    tiles,
                    total,
                }));
            }
            std::thread::sleep(pause);
            pause = (pause * 2).min(Duration::from_millis(5));
        }
        Ok(None)
    }

    /// The error that stops a frame before its next tile, if any: a
    /// cancelled token, or a deadline that has passed.
    pub(super) fn stop(&self, launched: Instant, tiles: usize, total: usize) -> Option<Error> {
        if self
            .options
            .cancel
            .as_ref()
            .is_some_and(CancelToken::is_cancelled)
        {
            return Some(Error::Cancelled { tiles, total });
        }
        match self.options.deadline {
            Some(deadline) if launched.elapsed() >= deadline => Some(Error::Deadline {
                deadline,
                tiles,
                total,
            }),
            _ => None,
        }
    }

    /// Uploads the frame's inputs, launches every tile and waits for them.
    /// Returns the kernel time and whether it comes from profiling events.
    pub(super) fn run(
        &mut self,
        width: u32,
        height: u32,
        outputs: Outputs,
    ) -> Result<(Duration, bool)> {
        if self.abandoned {
            return Err(Error::OpenCl(
                "an earlier frame's launch was abandoned at its deadline and may still be \
                 running on the device: make a new renderer"
                    .into(),
            ));
        }
        self.timing = None;
        check_size(width, height)?;
        let view = self.viewport(width, height)?;
        // The kernel renders `width` × `height` pixels, each covering
        // `scale` × `scale` pixels of the image `view` maps.
        let scale = self.scale();
        let (width, height) = self.rendered_size(width, height);
        let info = &self.selected.info;
        let progressive = self.pass >= 0;
        if self.targets.fits(width, height, outputs, progressive) {
            let host = frame_host_bytes(info, width, height, outputs, None);
            check_host_memory(width, height, host, available_host_memory())?;
        } else {
            // Free the old buffers first so their memory can be reused.
            self.targets = Targets::new(&self.queue, 1, 1, Outputs::Image, false)?;
            check_device_memory(info, width, height, outputs, progressive)?;
            let device = Targets::bytes(width, height, outputs, progressive)
                .iter()
                .sum();
            let host = frame_host_bytes(info, width, height, outputs, Some(device));
            check_host_memory(width, height, host, available_host_memory())?;
            self.targets = Targets::new(&self.queue, width, height, outputs, progressive)
                .map_err(|e| too_large(width, height, &format!("{e}")))?;
        }
        check_frame_inputs(
            &view,
            self.scene.lights(),
            self.source.origin,
            self.source.precision.limits(),
        )?;
        self.inputs.upload(
            &self.queue,
            &self.kernel,
            &view.pack(self.source.origin, scale),
            &self.values,
            self.scene.lights(),
            &self.source,
        )?;
        let k = &self.kernel;
        let t = &self.targets;
        let set = |a: RenderArg, v: i32| k.set_arg(a.index(), v).map_err(opencl);
        #[allow(clippy::cast_possible_wrap)] // sizes are at most MAX_IMAGE_SIDE
        {
            set(RenderArg::Width, width as i32)?;
            set(RenderArg::Height, height as i32)?;
        }
        set(RenderArg::WriteAovs, outputs.write_aovs())?;
        set(RenderArg::Pass, self.pass)?;
        set(RenderArg::RefineOnly, i32::from(self.refine_only))?;
        t.bind(k)?;
        let launched = Instant::now();
        let mut events: Vec<Event> = Vec::new();
        // The queue is in order: every tile starts after the coarse pass.
        let coarse = match &self.cone {
            Some(cone) => Some(self.coarse_pass(cone, width, height)?),
            None => None,
        };
        let brute = match &mut self.brute {
            Some(pass) => {
                let samples = self.options.quality.supersampling.max(1).pow(2);
                Some(pass.run(
                    &self.queue,
                    &self.inputs,
                    k,
                    (width, height, samples),
                    self.pass,
                )?)
            }
            None => None,
        };
        let (share, shares) = self.share;
        let mine = || {
            dispatch::tiles(width, height, self.options.tile_size)
                .enumerate()
                .filter(move |(i, _)| i % shares == share)
                .map(|(_, tile)| tile)
        };
        let total = mine().count();
        for tile in mine() {
            if let Some(stop) = self.stop(launched, events.len(), total) {
                // Let the tiles in flight finish before the buffers are
                // touched again.
                if let Some(e) = self.settle(events.last(), launched, (events.len(), total))? {
                    self.abandoned = true;
                    return Err(e);
                }
                return Err(stop);
            }
            let before = events.len().checked_sub(TILES_IN_FLIGHT);
            if let Some(e) =
                self.settle(before.map(|i| &events[i]), launched, (events.len(), total))?
            {
                self.abandoned = true;
                return Err(e);
            }
            #[allow(clippy::cast_possible_wrap)]
            {
                set(RenderArg::X0, tile.x as i32)?;
                set(RenderArg::Y0, tile.y as i32)?;
                set(RenderArg::TileWidth, tile.width as i32)?;
                set(RenderArg::TileHeight, tile.height as i32)?;
            }
            let global = dispatch::global_size(tile, self.local);
            // SAFETY: every buffer argument is alive in `self`, and the
            // kernel bounds-checks every work item against the tile.
            let mut event = Event::empty();
            unsafe {
                k.cmd()
                    .global_work_size(global)
                    .local_work_size(self.local)
                    .enew(&mut event)
                    .enq()
                    .map_err(opencl)?;
            }
            events.push(event);
        }
        if let Some(e) = self.settle(events.last(), launched, (total, total))? {
            self.abandoned = true;
            return Err(e);
        }
        self.queue.finish().map_err(opencl)?;
        events.extend(coarse);
        events.extend(brute);
        Ok(match profiled_time(&events) {
            Some(kernel) => (kernel, true),
            None => (launched.elapsed(), false),
        })
    }
}

/// The shading layers from the kernel's flat `linear` (four floats a
/// pixel) and `layers` ([`layer::STRIDE`] a pixel) outputs; the positions
/// of hits move from the program's frame (about `origin`) to the scene's.
fn layers_of(linear: &[f32], flat: &[f32], hit: &[u8], origin: DVec3) -> Layers {
    let field = |f: Field| {
        flat.chunks_exact(layer::STRIDE)
            .map(move |px| &px[f.offset..f.offset + f.len])
    };
    #[allow(clippy::cast_possible_truncation)] // positions are within the kernel's limits
    let moved = |p: &[f32]| {
        let world = origin + DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]));
        [world.x as f32, world.y as f32, world.z as f32]
    };
    Layers {
        linear: linear
            .chunks_exact(4)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect(),
        position: field(layer::POSITION)
            .zip(hit)
            .map(|(p, &h)| if h == 0 { [0.0; 3] } else { moved(p) })
            .collect(),
        albedo: field(layer::ALBEDO).map(|c| [c[0], c[1], c[2]]).collect(),
        occlusion: field(layer::OCCLUSION).map(|c| c[0]).collect(),
        shadow: field(layer::SHADOW).map(|c| c[0]).collect(),
        trap: field(layer::TRAP).map(|c| c[0]).collect(),
        object: Vec::new(),
        material: Vec::new(),
    }
}
