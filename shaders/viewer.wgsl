// The page's 3D view: triangles flat-shaded by a fixed light, coloured per triangle (the
// receiver's annual mean sunlit fraction, or grey for shading geometry). Not part of counting.

struct Camera {
    view_proj: mat4x4<f32>,
    // Unit vector towards the light, world axes (x east, y north, z up).
    light: vec4<f32>,
};

@group(0) @binding(0) var<uniform> camera: Camera;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) colour: vec3<f32>,
};

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) colour: vec3<f32>,
};

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = camera.view_proj * vec4<f32>(v.position, 1.0);
    out.normal = v.normal;
    out.colour = v.colour;
    return out;
}

@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    // Both sides are lit alike so back faces of open meshes do not render black.
    let n = select(-in.normal, in.normal, front);
    let diffuse = max(dot(normalize(n), camera.light.xyz), 0.0);
    return vec4<f32>(in.colour * (0.55 + 0.45 * diffuse), 1.0);
}
