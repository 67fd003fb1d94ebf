//! The GPU side: device acquisition (kept apart from the work, so tests and
//! benchmarks hand in their own device), buffers mirroring the shader
//! structs, and one progressive-radiosity shot as a sequence of passes:
//! residual reduction, shooter selection, sample preparation, visibility
//! rendering, receiver pass, shooter reset (paper 004 Sec. 2.3, 4.2).
//!
//! Reproducibility: every sum runs in a fixed order (strided per-thread
//! loops and fixed trees, each texel accumulating its samples in order),
//! so reruns on the same adapter and driver give the same bits. Different
//! adapters (lavapipe vs a hardware GPU) differ in rounding (FMA
//! contraction, rasterization rules) and agree only within tolerances.

use crate::atlas::HIDDEN_CORNERS;
use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

/// The error when no Vulkan adapter exists: says what to install.
pub const NO_ADAPTER: &str =
    "no GPU adapter found (Vulkan): install Mesa's software Vulkan driver lavapipe (Debian/Ubuntu: apt-get install mesa-vulkan-drivers) or a GPU driver";

/// Keeps Mesa's device-selection Vulkan layer quiet where there is no
/// desktop session: without a valid `XDG_RUNTIME_DIR` the layer's probe for
/// a Wayland display prints "error: XDG_RUNTIME_DIR is invalid" twice on
/// every successful run. The layer only reorders adapters, and
/// [`acquire`] chooses its adapter itself, so it is switched off
/// (`NODEVICE_SELECT=1`) in that case. Call it first thing in `main`,
/// before any thread exists (it sets an environment variable).
pub fn quiet_device_select_layer() {
    let session = std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| std::path::Path::new(&d).is_dir());
    if !session && std::env::var_os("NODEVICE_SELECT").is_none() {
        std::env::set_var("NODEVICE_SELECT", "1");
    }
}

/// Acquires a device and queue on the best Vulkan adapter (a hardware GPU
/// before lavapipe), with the adapter's own limits (the solver binds nine
/// storage buffers to one stage; WebGPU's default allows eight).
pub fn acquire() -> Result<(wgpu::Device, wgpu::Queue, wgpu::AdapterInfo), String> {
    let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle();
    descriptor.backends = wgpu::Backends::VULKAN;
    let instance = wgpu::Instance::new(descriptor);
    let options = wgpu::RequestAdapterOptions { power_preference: wgpu::PowerPreference::HighPerformance, ..Default::default() };
    let adapter = match pollster::block_on(instance.request_adapter(&options)) {
        Ok(a) => a,
        Err(_) => {
            let fallback = wgpu::RequestAdapterOptions { force_fallback_adapter: true, ..options };
            pollster::block_on(instance.request_adapter(&fallback)).map_err(|_| NO_ADAPTER.to_string())?
        }
    };
    let info = adapter.get_info();
    let descriptor = wgpu::DeviceDescriptor {
        label: Some("gpu-shoot"),
        required_features: wgpu::Features::empty(),
        required_limits: adapter.limits(),
        ..Default::default()
    };
    let (device, queue) =
        pollster::block_on(adapter.request_device(&descriptor)).map_err(|e| format!("the GPU adapter '{}' refused a device: {e}", info.name))?;
    Ok((device, queue, info))
}

/// One line naming an adapter.
pub fn describe(info: &wgpu::AdapterInfo) -> String {
    format!("{} ({:?}, {} {})", info.name, info.device_type, info.driver, info.driver_info)
}

/// Host mirror of `Params` in common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuParams {
    /// Covered texels in the atlas.
    pub n_texels: u32,
    /// Triangles.
    pub n_tris: u32,
    /// Triangle that shoots; `u32::MAX` for a light.
    pub shooter: u32,
    /// First sample of this batch.
    pub sample_first: u32,
    /// Samples in this batch.
    pub sample_count: u32,
    /// Visibility layers per sample: 6 (cube faces) or 1 (stereographic).
    pub layers_per_sample: u32,
    /// Visibility map side, pixels.
    pub res: u32,
    /// 0: cube faces; 1: stereographic.
    pub mode: u32,
    /// 1: ambient overshooting (004 Eq. 4.9).
    pub overshoot: u32,
    /// Groups (samples) of the shooter.
    pub group_count: u32,
    /// Reflection tree ([`crate::mirrors`]): 1 + the level of the node
    /// whose virtual samples shoot (0: the real samples).
    pub level: u32,
    /// Reflection tree: the first virtual sample.
    pub virtual_base: u32,
    /// Relative depth tolerance of the visibility test.
    pub tolerance: f32,
    /// Near plane of the cube faces, m.
    pub near: f32,
    /// Far distance, m.
    pub far: f32,
    /// Sum of triangle areas, m².
    pub total_area: f32,
    /// rgb: the interreflection factor R of 004 Eq. 2.6, per channel.
    pub interreflection: [f32; 4],
}

/// Host mirror of `Texel` in solver.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuTexel {
    /// xyz: the point the texel stands for, m; w: its area, m².
    pub position_area: [f32; 4],
    /// xyz: normal; w: the triangle index's bits.
    pub normal_triangle: [f32; 4],
    /// rgb: diffuse reflectance (its material's, or its texture's over the
    /// texel); w: 1 for a hypotenuse texel (half a square).
    pub rho: [f32; 4],
    /// xyz: the normal of the cosines (a normal map's perturbed normal,
    /// else `normal`'s xyz); w: 0.
    pub shading: [f32; 4],
}

/// Host mirror of `Tri` in solver.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuTri {
    /// First covered texel of the triangle.
    pub first: u32,
    /// Covered texels of the triangle.
    pub count: u32,
    /// First group (sample) of the triangle.
    pub group_first: u32,
    /// Groups (samples) of the shooter.
    pub group_count: u32,
    /// Triangle area, m² (its opaque part under an alpha mask).
    pub area: f32,
    /// Area of an interior texel, m², masks aside (`Region::texel_area`).
    pub texel_area: f32,
    /// Padding to the WGSL layout.
    pub _pad: [f32; 2],
    /// rgb: diffuse reflectance of its material.
    pub rho: [f32; 4],
    /// xyz: `(P1 - P0) / (2 size)`, half a texel edge, m (the near-field patch).
    pub half_u: [f32; 4],
    /// xyz: `(P2 - P0) / (2 size)`, half a texel edge, m.
    pub half_v: [f32; 4],
}

/// Host mirror of `Group` in solver.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuGroup {
    /// First texel of the group.
    pub first: u32,
    /// Texels in the group.
    pub count: u32,
    /// Padding to the WGSL layout.
    pub _pad: [u32; 2],
}

/// Host mirror of `Sample` in common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct GpuSample {
    /// xyz: sample position, m; w: area of the group, m² (0 for a light).
    pub position_area: [f32; 4],
    /// Frame tangent (light: r0, the C0 direction).
    pub t: [f32; 4],
    /// Frame bitangent (light: u0).
    pub b: [f32; 4],
    /// Frame normal (light: n0, the nadir).
    pub n: [f32; 4],
    /// rgb: unshot radiosity (area sample) or I_max in W/sr (light); w: 0 area, 1 light.
    pub power: [f32; 4],
    /// xyz: the group's normal for its cosine (its texels' mean perturbed
    /// normal under a normal map, else `n`); w: the opaque fraction of
    /// `polygon` (1 without an alpha mask).
    pub shading: [f32; 4],
    /// xyz: the corners of the part of the shooter the group covers
    /// ([`crate::atlas::Group::polygon`]), m; w of the first: their number
    /// (0 for a light), of the second: its area ([`crate::atlas::Group::extent`]).
    pub polygon: [[f32; 4]; 5],
    /// xyz: the corners of its buried part ([`crate::atlas::Group::hidden`]),
    /// m; w of the first: their number (0: none).
    pub hidden: [[f32; 4]; HIDDEN_CORNERS],
    /// The group's quadrants, written by the GPU (`prepare_samples`):
    /// their centroids and areas, and their unshot power about the mean.
    pub quadrants: [[f32; 4]; 8],
}

/// Host mirror of `Selection` in solver.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuSelection {
    /// x: the triangle with the largest score.
    pub shooter: [u32; 4],
    /// rgb: dB' of the shooter (004 Eq. 4.9), 0 without overshooting.
    pub overshoot: [f32; 4],
    /// rgb: ambient term (004 Eq. 2.4-2.6), W/m².
    pub ambient: [f32; 4],
    /// rgb: sum dB A over covered texels, W.
    pub unshot: [f32; 4],
    /// rgb: sum |dB| A, W.
    pub unshot_abs: [f32; 4],
    /// x: the shooter's |dB + dB'| A summed over channels, W.
    pub score: [f32; 4],
}

/// Everything the solver keeps on the device.
pub struct Gpu {
    /// Covered texels.
    pub texel_count: u32,
    /// Triangles.
    pub tri_count: u32,
    params: wgpu::Buffer,
    /// Radiosity per covered texel (vec4, rgb), W/m².
    pub radiosity: wgpu::Buffer,
    /// Residual per covered texel (vec4, rgb), W/m².
    pub residual: wgpu::Buffer,
    /// Per triangle: `sum dB A` (rgb, w: area) and `sum |dB| A`.
    pub tri_power: wgpu::Buffer,
    selection: wgpu::Buffer,
    samples: wgpu::Buffer,
    ldt: wgpu::Buffer,
    vertex_count: u32,
    compute_group: wgpu::BindGroup,
    render_group: wgpu::BindGroup,
    reduce: wgpu::ComputePipeline,
    select: wgpu::ComputePipeline,
    prepare: wgpu::ComputePipeline,
    finish: wgpu::ComputePipeline,
    receive: wgpu::ComputePipeline,
    /// The adaptive subdivision's count pass and its per-triangle counters.
    count: Option<(wgpu::ComputePipeline, wgpu::Buffer)>,
    /// Diffuse transmission's receiver pass (storing each texel's
    /// irradiance) and its pass adding `rho_d H + tau_d H_twin`.
    transmit: Option<[wgpu::ComputePipeline; 2]>,
    render: wgpu::RenderPipeline,
    /// The reflection tree's, where a material is specular.
    mirrors: Option<Mirrors>,
    layer_views: Vec<wgpu::TextureView>,
    depth_view: wgpu::TextureView,
    /// Visibility map side, pixels.
    pub res: u32,
    /// Layers of the visibility array (samples per batch x layers per sample).
    pub layers: u32,
    /// Most samples the samples buffer holds.
    pub sample_capacity: u32,
}

fn storage(binding: u32, visibility: wgpu::ShaderStages, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Storage { read_only }, has_dynamic_offset: false, min_binding_size: None },
        count: None,
    }
}

fn uniform(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Uniform, has_dynamic_offset: false, min_binding_size: None },
        count: None,
    }
}

/// What the GPU solver is built from.
pub struct Setup<'a> {
    /// The covered texels.
    pub texels: &'a [GpuTexel],
    /// The triangles.
    pub tris: &'a [GpuTri],
    /// The shooting samples (texel groups).
    pub groups: &'a [GpuGroup],
    /// Initial radiosity per texel (rgb, 0): the emission, or what a
    /// subdivided tile copied down.
    pub radiosity: &'a [[f32; 4]],
    /// Initial residual per texel (rgb, 0).
    pub residual: &'a [[f32; 4]],
    /// Triangle corners, 3 per triangle (xyz, 1).
    pub vertices: &'a [[f32; 4]],
    /// Visibility map side, pixels.
    pub res: u32,
    /// Layers of the visibility texture array.
    pub layers: u32,
    /// Largest number of samples in one shot.
    pub sample_capacity: u32,
    /// Largest light distribution table, floats.
    pub ldt_capacity: usize,
    /// The alpha masks for the visibility maps' test
    /// ([`crate::detail::Detail::mask_tables`]), where some triangle has one.
    pub masks: Option<(&'a [[f32; 4]], &'a [f32])>,
    /// Build the visibility count of the adaptive subdivision.
    pub adaptive: bool,
    /// Per texel, its diffuse transmittance (xyz) and the bits of its
    /// twin texel (w, `u32::MAX` for none), where a material transmits.
    pub transmission: Option<&'a [[f32; 4]]>,
    /// The reflection tree's tables, where a material is specular.
    pub mirrors: Option<MirrorSetup<'a>>,
}

/// What the reflection tree ([`crate::mirrors`]) needs on the device.
pub struct MirrorSetup<'a> {
    /// Per triangle: 1 where its material reflects or transmits specularly.
    pub specular: &'a [u32],
    /// Levels of a branch (the depth bound, plus one to find what it cuts).
    pub levels: usize,
    /// Window entries per level: the specular triangles.
    pub windows_per_level: usize,
    /// Virtual samples per level: the batch.
    pub views_per_level: usize,
}

/// Host mirror of `Level` in mirrors_common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuLevel {
    /// xyz: the window's unit normal, w: offset; the node's virtual
    /// shooter lies on the negative side.
    pub plane: [f32; 4],
    /// x: first window entry, y: entries, z: first layer of its maps.
    pub window: [u32; 4],
}

/// Host mirror of `View` in mirrors_common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuView {
    /// xyz: the frustum's right axis times k.
    pub right: [f32; 4],
    /// xyz: its up axis times k.
    pub up: [f32; 4],
    /// xyz: its axis; w: k = 1 / tan(half the field of view).
    pub axis: [f32; 4],
}

/// A node of the reflection tree as the GPU reads it.
pub struct NodeData<'a> {
    /// Its plane and first layer (the window range is filled in).
    pub level: GpuLevel,
    /// Its window entries: rgb the coefficient, w the triangle's bits.
    pub windows: &'a [[f32; 4]],
    /// Its virtual samples, one per sample of the batch.
    pub samples: &'a [GpuSample],
    /// Their frustums.
    pub views: &'a [GpuView],
}

/// The reflection tree's buffers and passes on the device.
struct Mirrors {
    levels: wgpu::Buffer,
    windows: wgpu::Buffer,
    views: wgpu::Buffer,
    hits: wgpu::Buffer,
    specular: Vec<u32>,
    windows_per_level: usize,
    render: wgpu::RenderPipeline,
    mark: wgpu::ComputePipeline,
}

const SAMPLE_SIZE: u64 = std::mem::size_of::<GpuSample>() as u64;

impl Gpu {
    /// Uploads the atlas and builds the pipelines.
    pub fn new(device: &wgpu::Device, setup: &Setup) -> Gpu {
        let init = |label: &str, contents: &[u8], usage: wgpu::BufferUsages| {
            // A zero-sized storage binding is invalid: keep at least 16 bytes.
            let mut bytes = contents.to_vec();
            bytes.resize(bytes.len().max(16), 0);
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents: &bytes, usage })
        };
        let rw = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("params"),
            size: std::mem::size_of::<GpuParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let texels = init("texels", bytemuck::cast_slice(setup.texels), rw);
        let radiosity = init("radiosity", bytemuck::cast_slice(setup.radiosity), rw);
        let residual = init("residual", bytemuck::cast_slice(setup.residual), rw);
        let tris = init("tris", bytemuck::cast_slice(setup.tris), rw);
        let groups = init("groups", bytemuck::cast_slice(setup.groups), rw);
        let tri_power = init("tri_power", &vec![0u8; setup.tris.len() * 32], rw);
        let selection = init("selection", &[0u8; std::mem::size_of::<GpuSelection>()], rw);
        let samples = init("samples", &vec![0u8; setup.sample_capacity.max(1) as usize * SAMPLE_SIZE as usize], rw);
        let ldt = init("ldt", &vec![0u8; setup.ldt_capacity.max(4) * 4], rw);
        let vertices = init("vertices", bytemuck::cast_slice(setup.vertices), wgpu::BufferUsages::STORAGE);

        let visibility = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("visibility"),
            size: wgpu::Extent3d { width: setup.res, height: setup.res, depth_or_array_layers: setup.layers },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::R32Float,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let array_view = visibility.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let layer_views = (0..setup.layers)
            .map(|layer| {
                visibility.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: layer,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        let depth = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("depth"),
            size: wgpu::Extent3d { width: setup.res, height: setup.res, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Depth32Float,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        let depth_view = depth.create_view(&Default::default());

        let common = include_str!("shaders/common.wgsl");
        let mut solver_source = format!("{common}\n{}", include_str!("shaders/solver.wgsl"));
        let mut render_source = format!("{common}\n{}", include_str!("shaders/visibility.wgsl"));
        // The reflection tree's code only for a scene that needs it.
        if setup.mirrors.is_some() {
            let tree = include_str!("shaders/mirrors_common.wgsl");
            solver_source += &format!("\n{tree}\n{}", include_str!("shaders/mirrors.wgsl"));
            render_source += &format!("\n{tree}\n{}", include_str!("shaders/visibility_mirrors.wgsl"));
        } else {
            solver_source += &format!("\n{}", include_str!("shaders/gather.wgsl"));
        }
        let solver_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("solver.wgsl"),
            source: wgpu::ShaderSource::Wgsl(solver_source.into()),
        });
        let render_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("visibility.wgsl"),
            source: wgpu::ShaderSource::Wgsl(render_source.into()),
        });

        let c = wgpu::ShaderStages::COMPUTE;
        let mut entries = vec![uniform(0, c)];
        entries.extend((1..=9).map(|b| storage(b, c, false)));
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: 10,
            visibility: c,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2Array,
                multisampled: false,
            },
            count: None,
        });
        entries.push(storage(11, c, true));
        let counts = setup.adaptive.then(|| init("counts", &vec![0u8; setup.tris.len() * 8], rw));
        if counts.is_some() {
            entries.push(storage(12, c, false));
        }
        // Diffuse transmission: the table and the irradiance per texel,
        // allocated only where a material transmits.
        let transmission = setup.transmission.map(|table| {
            [init("transmission", bytemuck::cast_slice(table), wgpu::BufferUsages::STORAGE), init("received", &vec![0u8; table.len() * 16], rw)]
        });
        if transmission.is_some() {
            entries.extend([storage(13, c, true), storage(14, c, false)]);
        }
        // The reflection tree: its branch, window entries, frustums and hits.
        let mirror_buffers = setup.mirrors.as_ref().map(|m| {
            let copy = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
            [
                init("levels", &vec![0u8; m.levels * std::mem::size_of::<GpuLevel>()], copy),
                init("windows", &vec![0u8; m.levels * m.windows_per_level.max(1) * 16], copy),
                init("views", &vec![0u8; m.levels * m.views_per_level.max(1) * std::mem::size_of::<GpuView>()], copy),
                init("hits", bytemuck::cast_slice(m.specular), rw),
            ]
        });
        if mirror_buffers.is_some() {
            entries.extend([storage(15, c, true), storage(16, c, true), storage(17, c, true), storage(18, c, false)]);
        }
        let compute_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("solver"), entries: &entries });
        let buffers = [&params, &texels, &radiosity, &residual, &tris, &groups, &tri_power, &selection, &samples, &ldt];
        let mut bind: Vec<wgpu::BindGroupEntry> =
            buffers.iter().enumerate().map(|(i, b)| wgpu::BindGroupEntry { binding: i as u32, resource: b.as_entire_binding() }).collect();
        bind.push(wgpu::BindGroupEntry { binding: 10, resource: wgpu::BindingResource::TextureView(&array_view) });
        bind.push(wgpu::BindGroupEntry { binding: 11, resource: vertices.as_entire_binding() });
        if let Some(buffer) = &counts {
            bind.push(wgpu::BindGroupEntry { binding: 12, resource: buffer.as_entire_binding() });
        }
        for (k, buffer) in transmission.iter().flatten().enumerate() {
            bind.push(wgpu::BindGroupEntry { binding: 13 + k as u32, resource: buffer.as_entire_binding() });
        }
        for (k, buffer) in mirror_buffers.iter().flatten().enumerate() {
            bind.push(wgpu::BindGroupEntry { binding: 15 + k as u32, resource: buffer.as_entire_binding() });
        }
        let compute_group = device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some("solver"), layout: &compute_layout, entries: &bind });
        let compute_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor { label: Some("solver"), bind_group_layouts: &[Some(&compute_layout)], immediate_size: 0 });
        let pipeline = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&compute_pipeline_layout),
                module: &solver_module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };

        // The masked fragment stage reads the samples and the corners too.
        let v = wgpu::ShaderStages::VERTEX;
        let vf = if setup.masks.is_some() || setup.mirrors.is_some() { v | wgpu::ShaderStages::FRAGMENT } else { v };
        let mut render_entries = vec![uniform(0, vf), storage(1, vf, true), storage(2, vf, true)];
        let mut render_bind = vec![
            wgpu::BindGroupEntry { binding: 0, resource: params.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: samples.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 2, resource: vertices.as_entire_binding() },
        ];
        // Alpha masks: two more tables for the fragment stage's test, and
        // its discarding entry point; a scene without masks allocates neither.
        let mask_buffers = setup.masks.map(|(triangles, texels)| {
            [init("mask_uvs", bytemuck::cast_slice(triangles), wgpu::BufferUsages::STORAGE), init("masks", bytemuck::cast_slice(texels), wgpu::BufferUsages::STORAGE)]
        });
        if let Some(buffers) = &mask_buffers {
            for (k, buffer) in buffers.iter().enumerate() {
                render_entries.push(storage(3 + k as u32, wgpu::ShaderStages::FRAGMENT, true));
                render_bind.push(wgpu::BindGroupEntry { binding: 3 + k as u32, resource: buffer.as_entire_binding() });
            }
        }
        // The frustum maps read the views and the branch's planes.
        if let Some([levels, _, views, _]) = &mirror_buffers {
            for (binding, buffer) in [(5, views), (6, levels)] {
                render_entries.push(storage(binding, v, true));
                render_bind.push(wgpu::BindGroupEntry { binding, resource: buffer.as_entire_binding() });
            }
        }
        let render_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("visibility"), entries: &render_entries });
        let render_group = device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some("visibility"), layout: &render_layout, entries: &render_bind });
        let render_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor { label: Some("visibility"), bind_group_layouts: &[Some(&render_layout)], immediate_size: 0 });
        let render_pipeline = |vertex: &str, fragment: &str| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(fragment),
                layout: Some(&render_pipeline_layout),
                vertex: wgpu::VertexState { module: &render_module, entry_point: Some(vertex), compilation_options: Default::default(), buffers: &[] },
                primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: wgpu::TextureFormat::Depth32Float,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &render_module,
                    entry_point: Some(fragment),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState { format: wgpu::TextureFormat::R32Float, blend: None, write_mask: wgpu::ColorWrites::ALL })],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let render = render_pipeline("vs", if mask_buffers.is_some() { "fs_masked" } else { "fs" });
        let mirrors = setup.mirrors.as_ref().zip(mirror_buffers).map(|(m, [levels, windows, views, hits])| Mirrors {
            levels,
            windows,
            views,
            hits,
            specular: m.specular.to_vec(),
            windows_per_level: m.windows_per_level.max(1),
            render: render_pipeline("vs_virtual", "fs_virtual"),
            mark: pipeline("mark_specular"),
        });
        Gpu {
            texel_count: setup.texels.len() as u32,
            tri_count: setup.tris.len() as u32,
            params,
            radiosity,
            residual,
            tri_power,
            selection,
            samples,
            ldt,
            vertex_count: setup.vertices.len() as u32,
            compute_group,
            render_group,
            reduce: pipeline("reduce"),
            select: pipeline("select_shooter"),
            prepare: pipeline("prepare_samples"),
            finish: pipeline("finish_shooter"),
            receive: pipeline("receive"),
            count: counts.map(|buffer| (pipeline("count_visible"), buffer)),
            transmit: transmission.map(|_| [pipeline("receive_translucent"), pipeline("transmit")]),
            render,
            mirrors,
            layer_views,
            depth_view,
            res: setup.res,
            layers: setup.layers,
            sample_capacity: setup.sample_capacity.max(1),
        }
    }

    fn dispatch(&self, encoder: &mut wgpu::CommandEncoder, pipeline: &wgpu::ComputePipeline, x: u32, y: u32) {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &self.compute_group, &[]);
        pass.dispatch_workgroups(x, y, 1);
    }

    /// Reduction and selection (004 Sec. 2.3): returns the selection.
    pub fn select(&self, device: &wgpu::Device, queue: &wgpu::Queue, params: &GpuParams) -> GpuSelection {
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(params));
        let mut encoder = device.create_command_encoder(&Default::default());
        let n = self.tri_count;
        self.dispatch(&mut encoder, &self.reduce, n.min(32768), n.div_ceil(32768));
        self.dispatch(&mut encoder, &self.select, 1, 1);
        queue.submit([encoder.finish()]);
        bytemuck::pod_read_unaligned(&read_buffer(device, queue, &self.selection, std::mem::size_of::<GpuSelection>() as u64))
    }

    /// Writes the samples of a shot (positions and frames; the powers of
    /// area samples are filled in on the GPU by `prepare`) and, for a
    /// light, its distribution table.
    pub fn upload_samples(&self, queue: &wgpu::Queue, samples: &[GpuSample], ldt: Option<&[f32]>) {
        queue.write_buffer(&self.samples, 0, bytemuck::cast_slice(samples));
        if let Some(table) = ldt {
            queue.write_buffer(&self.ldt, 0, bytemuck::cast_slice(table));
        }
    }

    /// Fills the powers of the shooter's samples from its residual.
    pub fn prepare(&self, device: &wgpu::Device, queue: &wgpu::Queue, params: &GpuParams) {
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(params));
        let mut encoder = device.create_command_encoder(&Default::default());
        self.dispatch(&mut encoder, &self.prepare, params.group_count.div_ceil(64), 1);
        queue.submit([encoder.finish()]);
    }

    /// Renders the visibility maps of one batch of samples and runs the
    /// receiver pass over every texel.
    pub fn shoot_batch(&self, device: &wgpu::Device, queue: &wgpu::Queue, params: &GpuParams, hemicube: bool) {
        self.batch(device, queue, params, hemicube, self.receiver_passes());
    }

    /// The receiver pass, or with diffuse transmission its two passes.
    fn receiver_passes(&self) -> &[wgpu::ComputePipeline] {
        match &self.transmit {
            Some(passes) => passes,
            None => std::slice::from_ref(&self.receive),
        }
    }

    /// Renders the visibility maps of one batch of samples and adds every
    /// triangle's visibility counts ([`Gpu::counts`]); the solver must
    /// have been built with `adaptive`.
    pub fn count_batch(&self, device: &wgpu::Device, queue: &wgpu::Queue, params: &GpuParams, hemicube: bool) {
        let (pipeline, _) = self.count.as_ref().expect("a solver built for adaptive subdivision");
        self.batch(device, queue, params, hemicube, std::slice::from_ref(pipeline));
    }

    /// Per triangle `[n_r, n_v]` since the last call (which clears them).
    pub fn counts(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Vec<[u32; 2]> {
        let (_, buffer) = self.count.as_ref().expect("a solver built for adaptive subdivision");
        let bytes = read_buffer(device, queue, buffer, self.tri_count as u64 * 8);
        queue.write_buffer(buffer, 0, &vec![0u8; self.tri_count as usize * 8]);
        bytemuck::pod_collect_to_vec(&bytes)
    }

    /// Renders the maps of a batch of samples, then runs `passes` over
    /// every texel, in order.
    fn batch(&self, device: &wgpu::Device, queue: &wgpu::Queue, params: &GpuParams, hemicube: bool, passes: &[wgpu::ComputePipeline]) {
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(params));
        let mut encoder = device.create_command_encoder(&Default::default());
        for sample in 0..params.sample_count {
            for face in 0..params.layers_per_sample {
                // A hemicube leaves out the face looking back (5) and needs
                // only the top half of the side faces (up = the normal).
                if hemicube && face == 5 {
                    continue;
                }
                let layer = sample * params.layers_per_sample + face;
                self.render_layer(&mut encoder, &self.render, layer, layer, hemicube && face > 0 && params.mode == 0);
            }
        }
        self.dispatch_texels(&mut encoder, passes);
        queue.submit([encoder.finish()]);
    }

    /// Renders instance `instance` of the scene with `pipeline` into
    /// visibility layer `layer` (its top half only where `half`).
    fn render_layer(&self, encoder: &mut wgpu::CommandEncoder, pipeline: &wgpu::RenderPipeline, layer: u32, instance: u32, half: bool) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: None,
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &self.layer_views[layer as usize],
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color { r: 1e30, g: 0.0, b: 0.0, a: 0.0 }), store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.depth_view,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Discard }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &self.render_group, &[]);
        if half {
            pass.set_scissor_rect(0, 0, self.res, self.res.div_ceil(2));
        }
        pass.draw(0..self.vertex_count, instance..instance + 1);
    }

    /// Runs `passes` over every texel, in order.
    fn dispatch_texels(&self, encoder: &mut wgpu::CommandEncoder, passes: &[wgpu::ComputePipeline]) {
        let groups = self.texel_count.div_ceil(64);
        let (x, y) = if groups <= 65535 { (groups.max(1), 1) } else { (65535, groups.div_ceil(65535)) };
        for pass in passes {
            self.dispatch(encoder, pass, x, y);
        }
    }

    /// Reads back the first `count` samples (their powers as `prepare`
    /// filled them), for the reflection tree's virtual samples.
    pub fn read_samples(&self, device: &wgpu::Device, queue: &wgpu::Queue, count: u32) -> Vec<GpuSample> {
        bytemuck::pod_collect_to_vec(&read_buffer(device, queue, &self.samples, count as u64 * SAMPLE_SIZE))
    }

    /// The reflection tree's state, for a solver built with `mirrors`.
    fn tree(&self) -> &Mirrors {
        self.mirrors.as_ref().expect("a solver built for specular materials")
    }

    /// Writes node `level` (0-based) of the branch: its plane and layers,
    /// its window entries, and its virtual samples (at `virtual_base +
    /// level count + i`) with their frustums.
    pub fn write_node(&self, queue: &wgpu::Queue, level: u32, virtual_base: u32, node: &NodeData) {
        let tree = self.tree();
        let first = level as usize * tree.windows_per_level;
        let plane = GpuLevel { window: [first as u32, node.windows.len() as u32, node.level.window[2], 0], ..node.level };
        queue.write_buffer(&tree.levels, level as u64 * std::mem::size_of::<GpuLevel>() as u64, bytemuck::bytes_of(&plane));
        queue.write_buffer(&tree.windows, first as u64 * 16, bytemuck::cast_slice(node.windows));
        let count = node.samples.len() as u64;
        queue.write_buffer(&self.samples, (virtual_base as u64 + level as u64 * count) * SAMPLE_SIZE, bytemuck::cast_slice(node.samples));
        queue.write_buffer(&tree.views, level as u64 * count * std::mem::size_of::<GpuView>() as u64, bytemuck::cast_slice(node.views));
    }

    /// Renders the frustum maps of the node at `params.level` (its
    /// virtual samples, into layers `first_layer ..`) and runs its
    /// receiver pass over every texel (004 Eq. 4.7-4.8).
    pub fn shoot_node(&self, device: &wgpu::Device, queue: &wgpu::Queue, params: &GpuParams, first_layer: u32) {
        let tree = self.tree();
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(params));
        let mut encoder = device.create_command_encoder(&Default::default());
        for i in 0..params.sample_count {
            self.render_layer(&mut encoder, &tree.render, first_layer + i, i, false);
        }
        self.dispatch_texels(&mut encoder, self.receiver_passes());
        queue.submit([encoder.finish()]);
    }

    /// The specular triangles that the pass at `params.level` lit (their
    /// texels gather light from the batch's samples at that level).
    pub fn lit_specular(&self, device: &wgpu::Device, queue: &wgpu::Queue, params: &GpuParams) -> Vec<u32> {
        let tree = self.tree();
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(params));
        let mut encoder = device.create_command_encoder(&Default::default());
        self.dispatch_texels(&mut encoder, std::slice::from_ref(&tree.mark));
        queue.submit([encoder.finish()]);
        let hits: Vec<u32> = bytemuck::pod_collect_to_vec(&read_buffer(device, queue, &tree.hits, self.tri_count as u64 * 4));
        queue.write_buffer(&tree.hits, 0, bytemuck::cast_slice(&tree.specular));
        hits.iter().enumerate().filter(|(_, &h)| h & 2 != 0).map(|(t, _)| t as u32).collect()
    }

    /// Sets the shooter's residual to -dB' (0 without overshooting).
    pub fn finish(&self, device: &wgpu::Device, queue: &wgpu::Queue, params: &GpuParams, shooter_texels: u32) {
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(params));
        let mut encoder = device.create_command_encoder(&Default::default());
        self.dispatch(&mut encoder, &self.finish, shooter_texels.div_ceil(64).max(1), 1);
        queue.submit([encoder.finish()]);
    }

    /// Reads back a vec4 buffer (radiosity, residual, tri_power).
    pub fn read_vec4(&self, device: &wgpu::Device, queue: &wgpu::Queue, buffer: &wgpu::Buffer, count: usize) -> Vec<[f32; 4]> {
        let bytes = read_buffer(device, queue, buffer, (count * 16) as u64);
        bytemuck::pod_collect_to_vec(&bytes)
    }
}

/// Copies `size` bytes of `buffer` to a mappable buffer and reads them.
pub fn read_buffer(device: &wgpu::Device, queue: &wgpu::Queue, buffer: &wgpu::Buffer, size: u64) -> Vec<u8> {
    let size = size.max(4);
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
    queue.submit([encoder.finish()]);
    staging.map_async(wgpu::MapMode::Read, .., |result| result.expect("mapping a readback buffer"));
    device.poll(wgpu::PollType::wait_indefinitely()).expect("waiting for the GPU");
    let bytes = staging.get_mapped_range(..).expect("mapped range").to_vec();
    staging.unmap();
    bytes
}
