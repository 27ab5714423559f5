//! The serde types of a scene file (SPEC §4): every table and key, with the spans
//! that locate a bad value. Unknown keys are refused here; values are checked in
//! [`super::validate`].

use serde::Deserialize;
use toml::Spanned;

use crate::limits;

pub(super) type V3 = Spanned<[f64; 3]>;
pub(super) type Num = Spanned<f64>;
pub(super) type Int = Spanned<i64>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FileScene {
    pub(super) camera: Option<Spanned<FileCamera>>,
    pub(super) image: Option<Spanned<FileImage>>,
    pub(super) sky: Option<FileSky>,
    pub(super) light: Option<Bounded<FileLight, LightLimit>>,
    pub(super) sphere: Option<Bounded<FileSphere, SphereLimit>>,
    pub(super) animation: Option<Spanned<FileAnimation>>,
}

/// A batch of `[[sphere]]` tables of a run (see [`super::streaming::SphereRun`]) parsed on its own.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FileSphereTable {
    pub(super) sphere: Vec<FileSphere>,
}

/// A cap on the length of an array in the file.
pub(super) trait Limit {
    const MAX: usize;
    const WHAT: &'static str;
}

pub(super) struct SphereLimit;
impl Limit for SphereLimit {
    const MAX: usize = limits::MAX_SPHERES;
    const WHAT: &'static str = "spheres";
}

pub(super) struct LightLimit;
impl Limit for LightLimit {
    const MAX: usize = limits::MAX_LIGHTS;
    const WHAT: &'static str = "lights";
}

/// An array that refuses its element number `L::MAX + 1` as soon as it is seen, rather
/// than after all of them have been collected.
pub(super) struct Bounded<T, L>(pub(super) Vec<T>, std::marker::PhantomData<L>);

impl<'de, T: Deserialize<'de>, L: Limit> Deserialize<'de> for Bounded<T, L> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visit<T, L>(std::marker::PhantomData<(T, L)>);
        impl<'de, T: Deserialize<'de>, L: Limit> serde::de::Visitor<'de> for Visit<T, L> {
            type Value = Bounded<T, L>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                write!(f, "an array of at most {} {}", L::MAX, L::WHAT)
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<Self::Value, A::Error> {
                let mut items = Vec::new();
                while let Some(item) = seq.next_element()? {
                    if items.len() == L::MAX {
                        return Err(serde::de::Error::custom(format!(
                            "more than {} {}: the limit is {}",
                            L::MAX,
                            L::WHAT,
                            L::MAX
                        )));
                    }
                    items.push(item);
                }
                Ok(Bounded(items, std::marker::PhantomData))
            }
        }
        d.deserialize_seq(Visit(std::marker::PhantomData))
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FileCamera {
    pub(super) look_from: Option<V3>,
    pub(super) look_at: Option<V3>,
    pub(super) up: Option<V3>,
    pub(super) vfov: Option<Num>,
    pub(super) origin: Option<V3>,
    pub(super) lower_left: Option<V3>,
    pub(super) horizontal: Option<V3>,
    pub(super) vertical: Option<V3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FileImage {
    pub(super) width: Option<Int>,
    pub(super) height: Option<Int>,
    pub(super) max_depth: Option<Int>,
    pub(super) spp: Option<Int>,
    pub(super) seed: Option<Int>,
    pub(super) quality: Option<Spanned<String>>,
    pub(super) encoding: Option<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FileSky {
    pub(super) down: Option<V3>,
    pub(super) up: Option<V3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FileLight {
    pub(super) position: Option<V3>,
    pub(super) intensity: Option<V3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FileSphere {
    pub(super) center: V3,
    pub(super) radius: Num,
    pub(super) color: Option<V3>,
    pub(super) reflect: Option<Num>,
    pub(super) transmit: Option<Num>,
    pub(super) ior: Option<Num>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FileAnimation {
    pub(super) frames: Option<Int>,
    pub(super) fps: Option<Num>,
    pub(super) orbit: Option<Num>,
    pub(super) key: Option<Vec<Spanned<FileKey>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FileKey {
    pub(super) frame: Int,
    pub(super) look_from: Option<V3>,
    pub(super) look_at: Option<V3>,
    pub(super) up: Option<V3>,
    pub(super) vfov: Option<Num>,
}
