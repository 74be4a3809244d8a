use railforce::contact::{Side, WheelOnRail, evaluate};
use railforce::vehicle::Vehicle;
fn main() {
    let v = Vehicle::load(std::path::Path::new("vehicles/c80.toml")).unwrap();
    let table = v.contact.table();
    let model = v.contact.model();
    let a = 0.29e-3;
    for j in 0..=40 {
        let y = 9.7295e-3 + j as f64 * 2e-8;
        let mut w = WheelOnRail::rolling(Side::Left, 16.7, 0.42, 0.0, 650.0);
        w.y = y;
        w.roll = table.lookup(y).roll;
        w.height = table.lookup(y).z - a;
        let f = evaluate(table, &model, &w);
        print!("y {:.5} a {:.1} Q {:.2} Y {:.2} ", y * 1e3, a * 1e6, f.force[2] * 1e-3, f.force[1] * 1e-3);
        for p in f.patches.iter().flatten() {
            print!("[N {:.1} ang {:.1} y {:.1}] ", p.normal * 1e-3, p.angle.to_degrees(), p.point[1] * 1e3);
        }
        println!();
    }
}
