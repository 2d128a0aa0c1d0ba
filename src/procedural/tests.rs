//! Scene-file parsing of [`Generator`], parameter validation and dispatch.

use super::*;

fn parse(text: &str) -> Result<Generator, toml::de::Error> {
    toml::from_str(text)
}

fn build_err(g: Generator) -> String {
    match g.build() {
        Ok(m) => panic!(
            "{g:?} built {} vertices, expected an error",
            m.vertices.len()
        ),
        Err(e) => e.to_string(),
    }
}

#[test]
fn toml_fills_defaults() {
    let g = parse("kind = \"torus\"\nmajor_radius = 2.0").unwrap();
    assert_eq!(
        g,
        Generator::Torus {
            major_radius: 2.0,
            minor_radius: 0.25,
            major_segments: 32,
            minor_segments: 18,
        }
    );
    assert_eq!(
        parse("kind = \"spiky_sphere\"").unwrap(),
        Generator::SpikySphere {
            radius: 1.0,
            subdivisions: 2,
            spike_length: 0.5,
        }
    );
}

#[test]
fn toml_integer_for_a_float_parameter() {
    let g = parse("kind = \"bowl\"\nradius = 3\nrings = 4").unwrap();
    assert_eq!(
        g,
        Generator::Bowl {
            radius: 3.0,
            rings: 4,
            segments: 32,
        }
    );
}

#[test]
fn toml_inline_table_in_a_scene() {
    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Object {
        generator: Generator,
    }
    let o: Object =
        toml::from_str("generator = { kind = \"hex_torus\", minor_radius = 0.3 }").unwrap();
    assert_eq!(
        o.generator,
        Generator::HexTorus {
            major_radius: 1.0,
            minor_radius: 0.3,
        }
    );
    let e = toml::from_str::<Object>("generator = { kind = \"net\", sagg = 0.1 }")
        .err()
        .expect("unknown key in an inline table accepted");
    assert!(e.to_string().contains("sagg"), "{e}");
}

#[test]
fn toml_rejects_unknown_keys() {
    for (text, key) in [
        ("kind = \"sphere_points\"\nradiuss = 1", "radiuss"),
        (
            "kind = \"torus\"\nmajor_radius = 2.0\nsegments = 8",
            "segments",
        ),
        ("kind = \"bucky_ball\"\nkind2 = \"x\"", "kind2"),
    ] {
        let e = parse(text).expect_err(text).to_string();
        assert!(
            e.contains("unknown field") && e.contains(key),
            "{text}: {e}"
        );
    }
}

#[test]
fn toml_rejects_bad_kind_and_types() {
    let e = parse("kind = \"doughnut\"").unwrap_err().to_string();
    assert!(e.contains("doughnut"), "{e}");
    assert!(parse("radius = 1.0").is_err(), "missing kind accepted");
    assert!(parse("kind = \"bucky_ball\"\nsides = 2.5").is_err());
    assert!(parse("kind = \"bucky_ball\"\nsides = -3").is_err());
    assert!(parse("kind = \"torus\"\nmajor_radius = \"big\"").is_err());
}

/// Builds every generator from `kind = "..."` alone and checks the SPEC 10 sizes.
#[test]
fn defaults_build_the_table_sizes() {
    let count = |kind: &str| {
        let m = parse(&format!("kind = \"{kind}\""))
            .unwrap()
            .build()
            .unwrap();
        assert_eq!(m.name, kind);
        m.validate(std::path::Path::new(kind)).unwrap();
        (m.vertices.len(), m.segments.len(), m.triangles.len())
    };
    assert_eq!(count("torus"), (576, 0, 1152));
    assert_eq!(count("hex_torus"), (36, 72, 0));
    assert_eq!(count("bowl"), (384, 736, 0));
    assert_eq!(count("net"), (91, 162, 0));
    assert_eq!(count("bucky_ball"), (6480, 0, 12_600));
    assert_eq!(count("sphere_points"), (2000, 0, 0));
    assert_eq!(count("spiky_sphere"), (324, 162, 320));
}

#[test]
fn rejects_bad_radii() {
    let torus = |major_radius, minor_radius| Generator::Torus {
        major_radius,
        minor_radius,
        major_segments: 32,
        minor_segments: 18,
    };
    let e = build_err(torus(-1.0, 0.25));
    assert!(
        e.contains("torus") && e.contains("major_radius") && e.contains("-1"),
        "{e}"
    );
    assert!(e.contains("greater than 0"), "{e}");
    let e = build_err(torus(1.0, f32::NAN));
    assert!(e.contains("minor_radius") && e.contains("NaN"), "{e}");
    let e = build_err(torus(1.0, 1.5));
    assert!(
        e.contains("minor_radius") && e.contains("major_radius"),
        "{e}"
    );
    let e = build_err(Generator::HexTorus {
        major_radius: 1.0,
        minor_radius: 1.0,
    });
    assert!(e.contains("hex_torus") && e.contains("minor_radius"), "{e}");
    let e = build_err(Generator::SpherePoints {
        radius: 0.0,
        count: 10,
    });
    assert!(e.contains("radius") && e.contains("= 0"), "{e}");
    let e = build_err(Generator::BuckyBall {
        radius: 1.0,
        tube_radius: f32::INFINITY,
        sides: 10,
        segments: 7,
    });
    assert!(e.contains("tube_radius"), "{e}");
    let e = build_err(Generator::SpikySphere {
        radius: 1.0,
        subdivisions: 1,
        spike_length: 0.0,
    });
    assert!(e.contains("spike_length"), "{e}");
    let e = build_err(Generator::Net {
        width: 2.0,
        depth: -2.0,
        nx: 3,
        nz: 3,
        sag: 0.0,
    });
    assert!(e.contains("depth"), "{e}");
    // Zero and negative sag are fine (a flat net, a bump); a NaN is not.
    for sag in [0.0, -0.3] {
        let g = Generator::Net {
            width: 2.0,
            depth: 2.0,
            nx: 3,
            nz: 3,
            sag,
        };
        assert!(g.build().is_ok());
    }
    let e = build_err(Generator::Net {
        width: 2.0,
        depth: 2.0,
        nx: 3,
        nz: 3,
        sag: f32::NAN,
    });
    assert!(e.contains("sag"), "{e}");
}

#[test]
fn rejects_too_few_segments() {
    let e = build_err(Generator::Torus {
        major_radius: 1.0,
        minor_radius: 0.25,
        major_segments: 32,
        minor_segments: 2,
    });
    assert!(
        e.contains("minor_segments") && e.contains("= 2") && e.contains("at least 3"),
        "{e}"
    );
    let e = build_err(Generator::Bowl {
        radius: 1.0,
        rings: 1,
        segments: 32,
    });
    assert!(e.contains("rings") && e.contains("at least 2"), "{e}");
    let e = build_err(Generator::Net {
        width: 2.0,
        depth: 2.0,
        nx: 1,
        nz: 7,
        sag: 0.25,
    });
    assert!(e.contains("nx"), "{e}");
    let e = build_err(Generator::BuckyBall {
        radius: 1.0,
        tube_radius: 0.02,
        sides: 2,
        segments: 7,
    });
    assert!(e.contains("sides"), "{e}");
    let e = build_err(Generator::SpherePoints {
        radius: 1.0,
        count: 0,
    });
    assert!(e.contains("count") && e.contains("at least 1"), "{e}");
}

#[test]
fn rejects_absurd_counts_without_allocating() {
    let e = build_err(Generator::Torus {
        major_radius: 1.0,
        minor_radius: 0.25,
        major_segments: usize::MAX,
        minor_segments: usize::MAX,
    });
    assert!(e.contains("limit") && e.contains("major_segments"), "{e}");
    let e = build_err(Generator::SpikySphere {
        radius: 1.0,
        subdivisions: 11,
        spike_length: 0.5,
    });
    assert!(e.contains("subdivisions") && e.contains("limit"), "{e}");
    let e = build_err(Generator::SpikySphere {
        radius: 1.0,
        subdivisions: usize::MAX,
        spike_length: 0.5,
    });
    assert!(e.contains("limit"), "{e}");
    for g in [
        Generator::Bowl {
            radius: 1.0,
            rings: usize::MAX,
            segments: usize::MAX,
        },
        Generator::Net {
            width: 1.0,
            depth: 1.0,
            nx: usize::MAX,
            nz: 10_000,
            sag: 0.0,
        },
        Generator::BuckyBall {
            radius: 1.0,
            tube_radius: 0.01,
            sides: 1000,
            segments: 1000,
        },
        Generator::SpherePoints {
            radius: 1.0,
            count: 50_000_001,
        },
    ] {
        assert!(build_err(g).contains("limit"));
    }
}
