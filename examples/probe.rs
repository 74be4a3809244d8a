use railforce::sim::{SimConfig, Simulation, fidelity};
use railforce::vehicle::Vehicle;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let v = Vehicle::load(std::path::Path::new(&args[1])).unwrap();
    let kmh: f64 = args[2].parse().unwrap();
    let t = fidelity::smooth(std::path::Path::new("tracks/tangent.toml")).unwrap();
    let cfg = SimConfig { speed: kmh / 3.6, duration: 12.0, settle: 0.0, initial_offset: 6e-3, ..SimConfig::default() };
    let mut sim = Simulation::new(&v, &t, cfg).unwrap();
    let mut i = 0;
    while sim.time() < 12.0 {
        sim.step().unwrap();
        i += 1;
        if i % 100 == 0 {
            let w = &sim.wheels;
            let st = sim.states();
            println!("{:.3} {:.3} {:.3} {:.3} {:.2} {:.2} {:.4}", sim.time(), w[0].y_centre*1e3, w[2].y_centre*1e3, w[4].y_centre*1e3, w[0].y*1e-3, w[1].y*1e-3, st[0].position.y*1e3);
        }
    }
}
