//! Tiles PNG images into one contact sheet: `montage OUT.png COLUMNS IN1.png IN2.png ...`.
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let cols: u32 = a[2].parse().unwrap();
    let imgs: Vec<image::RgbImage> = a[3..]
        .iter()
        .map(|p| image::open(p).unwrap().to_rgb8())
        .collect();
    let (w, h) = (imgs[0].width(), imgs[0].height());
    let rows = (imgs.len() as u32).div_ceil(cols);
    let mut out = image::RgbImage::from_pixel(w * cols, h * rows, image::Rgb([80, 80, 80]));
    for (k, im) in imgs.iter().enumerate() {
        let (cx, cy) = ((k as u32 % cols) * w, (k as u32 / cols) * h);
        for (x, y, p) in im.enumerate_pixels() {
            if x < w && y < h {
                out.put_pixel(cx + x, cy + y, *p);
            }
        }
    }
    out.save(&a[1]).unwrap();
}
