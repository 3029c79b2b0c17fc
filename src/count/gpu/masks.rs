//! Point masks: per map point and view, is the sun seen, read from the same tiles the counting
//! renders.
//!
//! A map's points are uploaded once ([`Counter::upload_points`]), grouped by receiver. A call to
//! [`Counter::masks`] plans, renders and counts its views exactly as [`Counter::fractions`] does
//! (same tiles, same atlas, same submission), and after the count pass a compute pass
//! (`shaders/point_masks.wgsl`) projects each point of every rendered member into its tile with
//! the tile's own camera and reads the id at its texel: lit when it is the receiver's own. One
//! render so serves both a view's fraction and its points' masks.
//!
//! Each rendered view's points come back as a packed bit mask (bit `j` of the view's words: the
//! receiver's `j`-th point in [`GpuPoints::points_of`] order). Views decided without a render
//! need no mask: a dark view (sun down or behind the receiver) has every point shaded, one with
//! nothing in front every point lit.
//!
//! Masks are counted at the counter's `resolution`, never adaptively: a point's answer is one
//! texel, which a coarse first side would decide at that side's texel size. A point is decided
//! by the texel whose centre is nearest it, so it can be wrong only within about one texel of a
//! shadow edge (the receiver's outline: see the shader's neighbour rule). See-through casters
//! are dithered per pixel as for counting: a point behind one is lit or not, with the
//! transmittance as its chance, not its fraction.

use std::ops::Range;

use super::pipelines::{GpuMaskView, WORDS_PER_MASK_GROUP, buffer, entry};
use super::plan::Tile;
use super::readback::MaskOut;
use super::{Counter, GpuScene};
use crate::count::view::SunView;
use crate::count::{ViewRequest, is_dark};
use crate::error::{Error, Result};

/// A map's points on a [`Counter`]'s device, grouped by receiver, with the buffers their masks
/// are written and read back through. Tied to the counter that uploaded it (its atlas).
pub struct GpuPoints {
    /// Per receiver, its points' range in the uploaded order (empty when it has none).
    ranges: Vec<Range<u32>>,
    /// Uploaded order → index of the point as given.
    order: Vec<u32>,
    /// Mask views one batch holds at most, and mask words.
    batch_views: u64,
    batch_words: u64,
    views: wgpu::Buffer,
    masks: wgpu::Buffer,
    /// [`super::readback::BATCHES_PER_READBACK`] batches' masks.
    pub(super) readback: wgpu::Buffer,
    bind: wgpu::BindGroup,
}

impl GpuPoints {
    /// Receiver `receiver`'s points, as indices into the points as given, in the order of their
    /// mask bits.
    pub fn points_of(&self, receiver: u32) -> &[u32] {
        match self.ranges.get(receiver as usize) {
            Some(r) => &self.order[r.start as usize..r.end as usize],
            None => &[],
        }
    }

    fn count_of(&self, receiver: u32) -> u32 {
        self.ranges.get(receiver as usize).map_or(0, |r| r.end - r.start)
    }
}

/// Where a rendered view's points were looked up: its camera and tile (tests derive the texel
/// size from it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaskTile {
    /// The tile's camera (scene coordinates relative to the scene origin → clip space).
    pub view: SunView,
    /// The tile's top-left pixel in the atlas (of its batch).
    pub atlas: [u32; 2],
    /// The tile's side in pixels.
    pub side: u32,
}

/// One view's answer for its receiver's points.
#[derive(Debug, Clone, PartialEq)]
pub enum PointMask {
    /// Sun down or behind the receiver: every point shaded.
    Dark,
    /// Nothing in front of the receiver: every point lit, without a render.
    Lit,
    /// Rendered: bit `j` of `words` (of [`Masks::words`]) is the receiver's `j`-th point.
    Rendered {
        /// The view's words in [`Masks::words`].
        words: Range<usize>,
        /// Its tile.
        tile: MaskTile,
    },
}

/// What [`Counter::masks`] answers: the views' counts and their points' masks, in request order.
#[derive(Debug, Clone, Default)]
pub struct Masks {
    /// Each view counted, as [`Counter::fractions`] counts it (with `count`).
    pub counted: Vec<super::Counted>,
    /// Each view's points.
    pub masks: Vec<PointMask>,
    /// The rendered views' packed bits.
    pub words: Vec<u32>,
}

impl Masks {
    /// Whether the `j`-th point (in [`GpuPoints::points_of`] order) of request `i`'s receiver
    /// sees the sun.
    pub fn lit(&self, i: usize, j: usize) -> bool {
        match &self.masks[i] {
            PointMask::Dark => false,
            PointMask::Lit => true,
            PointMask::Rendered { words, .. } => self.words[words.start + j / 32] >> (j % 32) & 1 == 1,
        }
    }
}

/// One batch's mask views and the request each answers.
pub(super) struct MaskBatch {
    pub(super) views: Vec<GpuMaskView>,
    pub(super) requests: Vec<usize>,
    pub(super) tiles: Vec<MaskTile>,
    pub(super) words: u64,
}

impl Counter {
    /// Uploads a map's points (world positions `3n`, each on receiver `receivers[i]`) for
    /// [`Self::masks`] on `scene`. Refuses a receiver id outside the scene and more points than
    /// one storage buffer of this device holds.
    pub fn upload_points(&self, scene: &GpuScene, positions: &[f32], receivers: &[u32]) -> Result<GpuPoints> {
        use wgpu::util::DeviceExt as _;
        let n = receivers.len();
        let count = scene.layout.receivers.len();
        if positions.len() != 3 * n {
            return Err(Error::argument("points", format!("{} coordinates for {n} points", positions.len())));
        }
        let mut by_receiver: Vec<Vec<u32>> = vec![Vec::new(); count];
        for (i, &r) in receivers.iter().enumerate() {
            by_receiver
                .get_mut(r as usize)
                .ok_or_else(|| Error::argument("points", format!("point {i} names receiver {r}; the scene has {count}")))?
                .push(i as u32);
        }
        let need = (n.max(1) * 16) as u64;
        let limit = self.device.limits().max_storage_buffer_binding_size;
        if need > limit {
            return Err(Error::argument(
                "points",
                format!("{n} points need a {need}-byte buffer, more than this GPU's {limit} bytes: use fewer points or the exact engine"),
            ));
        }
        let origin = scene.layout.origin;
        let mut ranges = Vec::with_capacity(count);
        let mut order = Vec::with_capacity(n);
        let mut relative: Vec<[f32; 4]> = Vec::with_capacity(n);
        for members in &by_receiver {
            let start = order.len() as u32;
            for &i in members {
                let p = 3 * i as usize;
                let world = glam::DVec3::new(positions[p].into(), positions[p + 1].into(), positions[p + 2].into());
                let q = (world - origin).as_vec3();
                relative.push([q.x, q.y, q.z, 1.0]);
            }
            order.extend_from_slice(members);
            ranges.push(start..order.len() as u32);
        }
        // A batch's tiles each hold one view group's members: at most the largest group's words.
        let words_of = |r: u32| u64::from(ranges[r as usize].len() as u32).div_ceil(32);
        let groups = &scene.layout.groups;
        let group_words = (0..groups.len() as u32).map(|g| groups.members(g).iter().map(|&m| words_of(m)).sum::<u64>());
        let per_tile = group_words.max().unwrap_or(0).max(1);
        let tiles = self.tiles_per_batch() as u64;
        let batch_views = tiles * crate::count::group::MAX_MEMBERS as u64;
        let batch_words = tiles * per_tile;
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        let points = self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("map points"),
            contents: if relative.is_empty() { &[0u8; 16] } else { bytemuck::cast_slice(&relative) },
            usage: storage,
        });
        let views = buffer(&self.device, "mask views", batch_views * size_of::<GpuMaskView>() as u64, storage);
        let masks = buffer(&self.device, "masks", batch_words * 4, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC);
        let readback = buffer(
            &self.device,
            "masks readback",
            batch_words * 4 * super::readback::BATCHES_PER_READBACK as u64,
            wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        );
        let bind = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("masks"),
            layout: &self.pipelines.mask_layout,
            entries: &[
                entry(0, wgpu::BindingResource::TextureView(&self.batch.atlas.ids)),
                entry(1, views.as_entire_binding()),
                entry(2, points.as_entire_binding()),
                entry(3, masks.as_entire_binding()),
            ],
        });
        self.check_errors("uploading map points")?;
        Ok(GpuPoints { ranges, order, batch_views, batch_words, views, masks, readback, bind })
    }

    /// Renders `requests` as [`Self::fractions`] does (at `resolution`, never adaptively) and
    /// answers, for each, whether each of its receiver's points in `points` sees the sun; with
    /// `count`, the same tiles' pixels are counted too (the fractions in [`Masks::counted`];
    /// without, a map that needs only its points skips the count pass, a third of a view's cost
    /// on lavapipe, and `counted` holds the cosines alone).
    pub async fn masks(&self, scene: &GpuScene, points: &GpuPoints, requests: &[ViewRequest], count: bool) -> Result<Masks> {
        let side = self.options.resolution;
        let mut counted = vec![super::Counted::default(); requests.len()];
        let tiles = super::plan::plan_tiles(&scene.layout, requests, side, &mut counted, &mut 0, false)?;
        let mut masks: Vec<Option<PointMask>> = vec![None; requests.len()];
        let mut words = Vec::new();
        let out = MaskOut { points, answers: &mut masks, words: &mut words, count };
        self.count_tiles(scene, requests, &tiles, side, &mut counted, Some(out)).await?;
        let masks = masks
            .into_iter()
            .zip(requests)
            .map(|(m, req)| {
                m.unwrap_or_else(|| {
                    let normal = scene.layout.receivers[req.receiver as usize].normal;
                    if is_dark(normal, req.sun) { PointMask::Dark } else { PointMask::Lit }
                })
            })
            .collect();
        Ok(Masks { counted, masks, words })
    }

    /// The mask views of one batch (tiles in atlas slots from 0 at side `side`): one per member
    /// with points, its words after those of the batch's earlier views.
    pub(super) fn mask_batch(
        &self,
        scene: &GpuScene,
        points: &GpuPoints,
        requests: &[ViewRequest],
        batch: &[Tile],
        side: u32,
    ) -> MaskBatch {
        let mut out = MaskBatch { views: Vec::new(), requests: Vec::new(), tiles: Vec::new(), words: 0 };
        for (slot, tile) in batch.iter().enumerate() {
            let origin = super::plan::tile_origin(self.atlas_side, slot, side);
            for &i in &tile.requests {
                let receiver = requests[i].receiver;
                let count = points.count_of(receiver);
                if count == 0 {
                    continue;
                }
                out.views.push(GpuMaskView {
                    view_proj: tile.view.view_proj.as_mat4().to_cols_array_2d(),
                    tile: origin,
                    side,
                    id: scene.layout.receivers[receiver as usize].gpu_id,
                    first_point: points.ranges[receiver as usize].start,
                    point_count: count,
                    first_word: out.words as u32,
                    _pad: 0,
                });
                out.requests.push(i);
                out.tiles.push(MaskTile { view: tile.view, atlas: origin, side });
                out.words += u64::from(count).div_ceil(32);
            }
        }
        out
    }

    /// Records the mask pass of `batch` (after its count pass) and copies its words into
    /// `points`'s readback from word `first_word` on.
    pub(super) fn encode_masks(&self, encoder: &mut wgpu::CommandEncoder, points: &GpuPoints, batch: &MaskBatch, first_word: u64) {
        if batch.views.is_empty() {
            return;
        }
        debug_assert!(batch.views.len() as u64 <= points.batch_views && batch.words <= points.batch_words);
        self.queue.write_buffer(&points.views, 0, bytemuck::cast_slice(&batch.views));
        let most = batch.views.iter().map(|v| v.point_count.div_ceil(32)).max().unwrap_or(0);
        // Enough workgroups that a large receiver's words spread, few enough that small ones
        // do not launch many idle ones; the shader strides over the rest.
        let groups = most.div_ceil(WORDS_PER_MASK_GROUP).clamp(1, 64);
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("masks"), timestamp_writes: None });
            pass.set_pipeline(&self.pipelines.mask);
            pass.set_bind_group(0, &points.bind, &[]);
            pass.dispatch_workgroups(groups, batch.views.len() as u32, 1);
        }
        encoder.copy_buffer_to_buffer(&points.masks, 0, &points.readback, first_word * 4, batch.words * 4);
    }
}
