//! The ASPRS standard point classes (LAS 1.4 R15, table 17) and their colours.
//!
//! ASPRS names the classes but gives no colours; these are QGIS's defaults for its
//! classified point-cloud renderer (`QgsPointCloudClassifiedRenderer::defaultCategories`),
//! the palette most lidar users see. Classes above 18 (reserved or user-defined) share a
//! neutral grey.

/// `(class, name, sRGB colour)` for the standard classes 0..=18.
pub const ASPRS_CLASSES: [(u8, &str, [u8; 3]); 19] = [
    (0, "created, never classified", [0xba, 0xba, 0xba]),
    (1, "unclassified", [0xaa, 0xaa, 0xaa]),
    (2, "ground", [0xaa, 0x55, 0x00]),
    (3, "low vegetation", [0x00, 0xaa, 0xaa]),
    (4, "medium vegetation", [0x55, 0xff, 0x55]),
    (5, "high vegetation", [0x00, 0xaa, 0x00]),
    (6, "building", [0xff, 0x55, 0x55]),
    (7, "low point (noise)", [0xaa, 0x00, 0x00]),
    (8, "reserved (model key-point)", [0x55, 0x55, 0x55]),
    (9, "water", [0x55, 0xff, 0xff]),
    (10, "rail", [0xaa, 0x00, 0xaa]),
    (11, "road surface", [0x00, 0x00, 0x00]),
    (12, "reserved (overlap)", [0x55, 0x55, 0x55]),
    (13, "wire - guard (shield)", [0xff, 0xff, 0x55]),
    (14, "wire - conductor (phase)", [0xff, 0xff, 0x55]),
    (15, "transmission tower", [0xff, 0x55, 0xff]),
    (16, "wire-structure connector", [0xff, 0xff, 0x55]),
    (17, "bridge deck", [0x55, 0x55, 0xff]),
    (18, "high noise", [0x64, 0x64, 0x64]),
];

/// Colour of classes without a standard colour (19..=255).
pub const OTHER_CLASS: [u8; 3] = [0x80, 0x80, 0x80];

/// The sRGB colour of ASPRS class `class`.
pub fn class_colour(class: u8) -> [u8; 3] {
    ASPRS_CLASSES
        .get(class as usize)
        .map_or(OTHER_CLASS, |&(_, _, c)| c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_is_indexed_by_class() {
        for (i, &(class, _, _)) in ASPRS_CLASSES.iter().enumerate() {
            assert_eq!(class as usize, i);
        }
        assert_eq!(class_colour(2), [0xaa, 0x55, 0x00]);
        assert_eq!(class_colour(200), OTHER_CLASS);
    }
}
