//! The clip to bake and its channels: each animated property of a node read into key times and
//! values, checked (element types, increasing finite times, values that fit the keys).

use super::validate::{check_accessor, NORMALISED};
use super::{buffer_data, Buffers};
use gltf::accessor::{DataType, Dimensions};
use gltf::animation::util::ReadOutputs;
use gltf::animation::{Interpolation, Property};

/// One animated property of one node: key times and the values at them, flattened.
#[derive(Debug)]
pub(super) struct Channel {
    pub(super) node: usize,
    pub(super) property: Property,
    pub(super) interpolation: Interpolation,
    pub(super) times: Vec<f32>,
    /// Per key `width` values; cubic splines store in-tangent, value, out-tangent per key.
    pub(super) values: Vec<f32>,
    /// Components per value: 3 (translation, scale), 4 (rotation) or the morph target count.
    pub(super) width: usize,
}

/// The clip named or numbered by `clip`, or the first; an error lists the clips there are.
pub(super) fn pick_clip<'a>(
    document: &'a gltf::Document,
    clip: Option<&str>,
) -> Result<gltf::Animation<'a>, String> {
    let mut clips = document.animations();
    let Some(wanted) = clip else {
        return clips.next().ok_or_else(|| {
            "no animation in the file (a still mesh: there is nothing to compress over time)".into()
        });
    };
    let by_name = document.animations().find(|a| a.name() == Some(wanted));
    let by_index = || {
        wanted
            .parse::<usize>()
            .ok()
            .and_then(|i| document.animations().nth(i))
    };
    by_name.or_else(by_index).ok_or_else(|| {
        let known: Vec<String> = document
            .animations()
            .map(|a| format!("{} `{}`", a.index(), a.name().unwrap_or("")))
            .collect();
        if known.is_empty() {
            format!("no clip `{wanted}`: the file has no animations")
        } else {
            format!("no clip `{wanted}`; the clips are {}", known.join(", "))
        }
    })
}

/// Every channel of the clip that has keys; a clip with none is an error.
pub(super) fn read_channels(
    animation: &gltf::Animation,
    data: Buffers,
) -> Result<Vec<Channel>, String> {
    let mut channels = Vec::new();
    for channel in animation.channels() {
        if let Some(read) = read_channel(animation, &channel, data)? {
            channels.push(read);
        }
    }
    if channels.is_empty() {
        return Err(format!("animation {} has no keyframes", animation.index()));
    }
    Ok(channels)
}

/// One channel, checked; `None` when it has no keys.
fn read_channel(
    animation: &gltf::Animation,
    channel: &gltf::animation::Channel,
    data: Buffers,
) -> Result<Option<Channel>, String> {
    let name = format!(
        "animation {} channel {}",
        animation.index(),
        channel.index()
    );
    check_channel_accessors(channel, &name)?;
    let (times, values) = read_keys(channel, data, &name)?;
    if times.is_empty() {
        return Ok(None);
    }
    if times.iter().any(|t| !t.is_finite()) || times.windows(2).any(|w| w[1] < w[0]) {
        return Err(format!(
            "{name}: key times are not increasing finite numbers"
        ));
    }
    let interpolation = channel.sampler().interpolation();
    let width = value_width(channel, interpolation, times.len(), values.len(), &name)?;
    if values.iter().any(|v| !v.is_finite()) {
        return Err(format!("{name}: a value is not a finite number"));
    }
    Ok(Some(Channel {
        node: channel.target().node().index(),
        property: channel.target().property(),
        interpolation,
        times,
        values,
        width,
    }))
}

/// Key times must be float scalars, values of the type the animated property takes.
fn check_channel_accessors(channel: &gltf::animation::Channel, name: &str) -> Result<(), String> {
    let sampler = channel.sampler();
    check_accessor(
        Some(sampler.input()),
        &format!("{name} key times"),
        Dimensions::Scalar,
        &[DataType::F32],
    )?;
    let (dimensions, types): (Dimensions, &[DataType]) = match channel.target().property() {
        Property::Translation | Property::Scale => (Dimensions::Vec3, &[DataType::F32]),
        Property::Rotation => (Dimensions::Vec4, &NORMALISED),
        Property::MorphTargetWeights => (Dimensions::Scalar, &NORMALISED),
    };
    check_accessor(
        Some(sampler.output()),
        &format!("{name} values"),
        dimensions,
        types,
    )
}

/// The channel's key times and its values, flattened to floats.
fn read_keys(
    channel: &gltf::animation::Channel,
    data: Buffers,
    name: &str,
) -> Result<(Vec<f32>, Vec<f32>), String> {
    let reader = channel.reader(|b| buffer_data(data, b));
    let times: Vec<f32> = reader
        .read_inputs()
        .ok_or_else(|| format!("{name}: key times unreadable"))?
        .collect();
    let values: Vec<f32> = match reader
        .read_outputs()
        .ok_or_else(|| format!("{name}: values unreadable"))?
    {
        ReadOutputs::Translations(it) => it.flatten().collect(),
        ReadOutputs::Scales(it) => it.flatten().collect(),
        ReadOutputs::Rotations(it) => it.into_f32().flatten().collect(),
        ReadOutputs::MorphTargetWeights(it) => it.into_f32().collect(),
    };
    Ok((times, values))
}

/// Components per value: the values must split evenly over the keys (three entries per key for
/// cubic splines), in the width the property takes.
fn value_width(
    channel: &gltf::animation::Channel,
    interpolation: Interpolation,
    keys: usize,
    values: usize,
    name: &str,
) -> Result<usize, String> {
    let per_key = keys
        * if interpolation == Interpolation::CubicSpline {
            3
        } else {
            1
        };
    let width = values / per_key;
    let expected_width = match channel.target().property() {
        Property::Translation | Property::Scale => Some(3),
        Property::Rotation => Some(4),
        Property::MorphTargetWeights => None,
    };
    if width == 0 || width * per_key != values || expected_width.is_some_and(|e| e != width) {
        return Err(format!("{name}: {values} values do not fit {keys} keys"));
    }
    Ok(width)
}
