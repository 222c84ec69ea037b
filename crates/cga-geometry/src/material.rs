//! Materials as CGA describes them (`material.*` shape attributes).

use std::sync::{Arc, LazyLock};

/// Shared strings for the defaults: a default material is made for every
/// new mesh, and `Arc::from("")` would allocate each time.
static EMPTY: LazyLock<Arc<str>> = LazyLock::new(|| Arc::from(""));
static SHADER: LazyLock<Arc<str>> = LazyLock::new(|| Arc::from("CityEngineShader"));
static BLEND: LazyLock<Arc<str>> = LazyLock::new(|| Arc::from("blend"));

/// The ten texture channels, in the order of CGA's texture layers / UV sets:
/// the channel at index `k` uses UV set `k`.
pub const TEXTURE_CHANNELS: [&str; 10] = [
    "colormap",
    "bumpmap",
    "dirtmap",
    "specularmap",
    "opacitymap",
    "normalmap",
    "emissivemap",
    "occlusionmap",
    "roughnessmap",
    "metallicmap",
];

/// One texture channel: the texture file and its transform (`su sv tu tv rw`).
#[derive(Clone, Debug, PartialEq)]
pub struct TextureChannel {
    /// Texture path as written in the rule (empty: no texture).
    pub path: Arc<str>,
    pub su: f64,
    pub sv: f64,
    pub tu: f64,
    pub tv: f64,
    pub rw: f64,
}

impl Default for TextureChannel {
    fn default() -> Self {
        TextureChannel {
            path: EMPTY.clone(),
            su: 1.0,
            sv: 1.0,
            tu: 0.0,
            tv: 0.0,
            rw: 0.0,
        }
    }
}

/// A material with CGA's defaults (white, opaque, no textures).
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: Arc<str>,
    pub shader: Arc<str>,
    /// Diffuse colour, non-linear sRGB in [0, 1].
    pub color: [f64; 3],
    pub ambient: [f64; 3],
    pub specular: [f64; 3],
    pub emissive: [f64; 3],
    pub opacity: f64,
    pub reflectivity: f64,
    pub shininess: f64,
    pub bump_value: f64,
    pub metallic: f64,
    pub roughness: f64,
    pub double_sided: bool,
    pub opacitymap_mode: Arc<str>,
    pub opacitymap_cutoff: f64,
    /// Indexed like [`TEXTURE_CHANNELS`].
    pub maps: [TextureChannel; 10],
}

impl Default for Material {
    fn default() -> Self {
        Material {
            name: EMPTY.clone(),
            shader: SHADER.clone(),
            color: [1.0; 3],
            ambient: [0.0; 3],
            specular: [0.0; 3],
            emissive: [0.0; 3],
            opacity: 1.0,
            reflectivity: 0.0,
            shininess: 1.0,
            bump_value: 1.0,
            metallic: 0.0,
            roughness: 1.0,
            double_sided: true,
            opacitymap_mode: BLEND.clone(),
            opacitymap_cutoff: 0.5,
            maps: Default::default(),
        }
    }
}

impl Material {
    /// The colour map (texture channel 0) path, empty if none.
    pub fn colormap(&self) -> &str {
        &self.maps[0].path
    }
}
