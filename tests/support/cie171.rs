//! Reference values of CIE 171:2006 test cases shared by the tests (name, position, exact
//! irradiance in W/m² for the case's source).

/// CIE 171:2006 case 5.3 (area source, direct only): a black 4 × 4 × 3 m room, a 1 × 1 m
/// Lambertian source of luminance 1000 (exitance π·1000) centred in the ceiling facing down;
/// `E = π L F(dA → source)` at points on the wall y = 0 (x = 2, z = 2.75 … 0.25) and on the floor
/// (x = 2, y = 0.25 … 3.75). Values: exact form factors (the report's table, computed
/// by discretising the source, differs from them by up to 0.26%).
pub const CASE_53_WALL: [(&str, f64, f64); 6] =
    [("A", 2.75, 32.677), ("B", 2.25, 75.194), ("C", 1.75, 81.323), ("D", 1.25, 69.061), ("E", 0.75, 53.404), ("F", 0.25, 40.002)];
/// Case 5.3's floor points (x = 2, at y).
pub const CASE_53_FLOOR: [(&str, f64, f64); 8] = [
    ("G", 0.25, 61.424),
    ("H", 0.75, 79.255),
    ("I", 1.25, 95.667),
    ("J", 1.75, 105.778),
    ("K", 2.25, 105.778),
    ("L", 2.75, 95.667),
    ("M", 3.25, 79.255),
    ("N", 3.75, 61.424),
];
