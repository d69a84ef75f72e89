//! Random small meshes (degenerate, non-manifold, repeated triangles, isolated
//! vertices): building never panics, and a built atlas keeps its promises.

use atlas::{build, sample, AtlasOptions};
use proptest::prelude::*;
use std::collections::HashSet;

fn mesh() -> impl Strategy<Value = (Vec<[f32; 3]>, Vec<[u32; 3]>, Vec<u32>)> {
    (3usize..40).prop_flat_map(|n| {
        let coord = -4i32..5; // small integer grid: many coplanar and coincident points
        (
            prop::collection::vec([coord.clone(), coord.clone(), coord], n),
            prop::collection::vec([0..n as u32, 0..n as u32, 0..n as u32], 0..50),
            prop::collection::vec(0u32..4, n),
        )
            .prop_map(|(p, t, c)| (p.into_iter().map(|q| q.map(|x| x as f32)).collect(), t, c))
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    #[test]
    fn never_panics_and_stays_injective((positions, triangles, partition) in mesh()) {
        let opts = AtlasOptions { width: 64, height: 64, ..AtlasOptions::default() };
        // Any input of this kind fits 64×64: it must build.
        let built = build(&positions, &triangles, &partition, &opts);
        prop_assert!(built.is_ok(), "{:?}", built.as_ref().err());
        if let Ok(atlas) = built {
            let px = atlas.vertex_pixels();
            prop_assert_eq!(px.iter().collect::<HashSet<_>>().len(), positions.len());
            for (v, p) in px.iter().enumerate() {
                prop_assert_eq!(atlas.chart_at(u32::from(p[0]), u32::from(p[1])), Some(atlas.vertex_charts()[v]));
            }
            let values: Vec<f32> = (0..positions.len()).map(|v| v as f32 * 1.5 - 7.0).collect();
            let back = sample(px, atlas.width(), &atlas.splat(&values));
            prop_assert_eq!(back.ok(), Some(values));
        }
    }
}
