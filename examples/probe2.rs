use railforce::contact::{Side, WheelOnRail, evaluate, height_for_load};
use railforce::vehicle::Vehicle;
fn main() {
    let v = Vehicle::load(std::path::Path::new("vehicles/c80.toml")).unwrap();
    let table = v.contact.table();
    let model = v.contact.model();
    for j in 0..=20 {
        let y = 9.73e-3 + j as f64 * 5e-7;
        let mut w = WheelOnRail::rolling(Side::Left, 16.7, 0.42, 0.0, 650.0);
        w.y = y;
        w.roll = table.lookup(y).roll;
        w.height = height_for_load(table, &model, &w, 122.6e3);
        let f = evaluate(table, &model, &w);
        let (i, t) = table.locate(y);
        print!("y {:.4} i {} t {:.3} appr {:.1}um Y {:.1} ", y * 1e3, i, t, (table.lookup(y).z - w.height) * 1e6, f.force[1] * 1e-3);
        for p in f.patches.iter().flatten() {
            print!("[N {:.1} ang {:.1} y {:.1}] ", p.normal * 1e-3, p.angle.to_degrees(), p.point[1] * 1e3);
        }
        println!();
    }
}
