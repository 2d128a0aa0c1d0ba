//! Tiles PNG images into one contact sheet: `montage OUT.png COLUMNS IN1.png IN2.png ...`.
fn main() {
    if let Err(e) = run() {
        eprintln!("montage: {e}");
        std::process::exit(2);
    }
}

fn run() -> Result<(), String> {
    let a: Vec<String> = std::env::args().collect();
    if a.len() < 4 {
        return Err("usage: montage OUT.png COLUMNS IN1.png [IN2.png ...]".into());
    }
    let cols: u32 = match a[2].parse() {
        Ok(c) if c > 0 => c,
        _ => {
            return Err(format!(
                "COLUMNS: expected a whole number >= 1, got '{}'",
                a[2]
            ));
        }
    };
    let imgs = a[3..]
        .iter()
        .map(|p| {
            image::open(p)
                .map(|i| i.to_rgb8())
                .map_err(|e| format!("{p}: {e}"))
        })
        .collect::<Result<Vec<image::RgbImage>, String>>()?;
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
    out.save(&a[1]).map_err(|e| format!("{}: {e}", a[1]))
}
