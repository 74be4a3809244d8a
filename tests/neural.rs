//! Networks: parameter counts, gradients against finite differences, determinism.

use railforce::learn::neural::{Architecture, NetConfig, Network};

fn config(architecture: Architecture, channels: usize, outputs: usize, dropout: f32) -> NetConfig {
    NetConfig {
        architecture,
        window: 20,
        channels,
        outputs,
        dropout,
        seed: 7,
    }
}

fn data(batch: usize, channels: usize, outputs: usize) -> (Vec<f32>, Vec<f32>) {
    let x = (0..batch * 20 * channels)
        .map(|i| ((i as f32) * 0.7310).sin() + 0.3 * ((i as f32) * 0.0137).cos())
        .collect();
    let y = (0..batch * outputs)
        .map(|i| ((i as f32) * 1.37).sin())
        .collect();
    (x, y)
}

fn loss(net: &mut Network, x: &[f32], y: &[f32], batch: usize) -> f64 {
    let out = net.forward(x, batch, true);
    out.iter()
        .zip(y)
        .map(|(p, t)| ((p - t) as f64).powi(2))
        .sum::<f64>()
        / y.len() as f64
}

#[test]
fn cnn_bilstm_has_the_spec_parameter_count() {
    // Spec learning.md §3: 462 + 42 + 2816 + 256 + 24000 + 2624 + 520 + 9 = 30 729.
    let net = Network::new(config(Architecture::CnnBiLstm, 21, 1, 0.2));
    assert_eq!(net.params.trainable_count(), 30_729);
    let both = Network::new(config(Architecture::CnnBiLstm, 21, 2, 0.2));
    assert_eq!(both.params.trainable_count(), 30_738);
}

#[test]
fn gradients_match_finite_differences() {
    for arch in [
        Architecture::CnnBiLstm,
        Architecture::Cnn,
        Architecture::BiLstm,
        Architecture::Gru,
    ] {
        let (batch, c, o) = (6, 5, 2);
        let mut net = Network::new(config(arch, c, o, 0.0));
        let (x, y) = data(batch, c, o);
        net.params.zero_grad();
        let out = net.forward(&x, batch, true).to_vec();
        let dout: Vec<f32> = out
            .iter()
            .zip(&y)
            .map(|(p, t)| 2.0 * (p - t) / y.len() as f32)
            .collect();
        net.backward(&x, &dout);
        let grad = net.params.grad.clone();
        // Directional derivative along a fixed pseudo-random direction over trainable slots,
        // plus single-coordinate checks of the largest gradient entries of every slot.
        let slots = net.params.slots.clone();
        for slot in slots.iter().filter(|s| s.trainable) {
            let r = slot.range();
            let (imax, gmax) = r
                .clone()
                .map(|i| (i, grad[i]))
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                .unwrap();
            if gmax.abs() < 1e-4 {
                continue;
            }
            let eps = 3e-4f32;
            let v0 = net.params.value[imax];
            net.params.value[imax] = v0 + eps;
            let lp = loss(&mut net, &x, &y, batch);
            net.params.value[imax] = v0 - eps;
            let lm = loss(&mut net, &x, &y, batch);
            net.params.value[imax] = v0;
            let fd = (lp - lm) / (2.0 * eps as f64);
            // The whole slot along a pseudo-random direction: every entry takes part.
            let dir: Vec<f32> = r.clone().map(|i| ((i as f32) * 12.9898).sin()).collect();
            let gv: f64 = r.clone().zip(&dir).map(|(i, d)| (grad[i] * d) as f64).sum();
            let base: Vec<f32> = net.params.value[r.clone()].to_vec();
            let along = |sign: f32, net: &mut Network| {
                for (k, i) in r.clone().enumerate() {
                    net.params.value[i] = base[k] + sign * eps * dir[k];
                }
                let l = loss(net, &x, &y, batch);
                net.params.value[r.clone()].copy_from_slice(&base);
                l
            };
            let fdv = (along(1.0, &mut net) - along(-1.0, &mut net)) / (2.0 * eps as f64);
            assert!(
                (fdv - gv).abs() / (gv.abs() + 5e-3) < 0.05,
                "{} {} (direction): analytic {gv:.6e}, finite difference {fdv:.6e}",
                arch.name(),
                slot.name
            );
            // f32 forward passes: a noise floor of ~1e-4 on the difference quotient.
            let rel = (fd - gmax as f64).abs() / (gmax.abs() as f64 + 5e-3);
            assert!(
                rel < 0.05,
                "{} {}: analytic {gmax:.6e}, finite difference {fd:.6e}",
                arch.name(),
                slot.name
            );
        }
    }
}

#[test]
fn same_seed_gives_same_weights_and_outputs() {
    let mut a = Network::new(config(Architecture::CnnBiLstm, 21, 1, 0.2));
    let mut b = Network::new(config(Architecture::CnnBiLstm, 21, 1, 0.2));
    assert_eq!(a.params.value, b.params.value);
    let (x, _) = data(4, 21, 1);
    assert_eq!(a.forward(&x, 4, true), b.forward(&x, 4, true));
    let mut other = config(Architecture::CnnBiLstm, 21, 1, 0.2);
    other.seed = 8;
    assert_ne!(Network::new(other).params.value, a.params.value);
}

#[test]
fn fused_evaluation_matches_the_layer_by_layer_path() {
    use railforce::learn::neural::Adam;
    for arch in [
        Architecture::CnnBiLstm,
        Architecture::Cnn,
        Architecture::BiLstm,
        Architecture::Gru,
    ] {
        let (c, o) = (21, 2);
        let mut net = Network::new(config(arch, c, o, 0.2));
        // A few training steps so that batch-norm running statistics and weights move away
        // from their initial values.
        let mut adam = Adam::new(net.params.value.len(), 1e-2);
        let (x, y) = data(32, c, o);
        for _ in 0..5 {
            net.params.zero_grad();
            let out = net.forward(&x, 32, true).to_vec();
            let dout: Vec<f32> = out.iter().zip(&y).map(|(p, t)| p - t).collect();
            net.backward(&x, &dout);
            adam.step(&mut net.params);
        }
        // 1 window, and 130 windows across the evaluation path's chunk boundaries.
        for batch in [1, 130] {
            let (x, _) = data(batch, c, o);
            let fused = net.forward(&x, batch, false).to_vec();
            let reference = net.forward_reference(&x, batch).to_vec();
            assert_eq!(fused.len(), batch * o);
            let scale = reference.iter().map(|v| v.abs()).fold(1e-3, f32::max);
            for (a, b) in fused.iter().zip(&reference) {
                assert!(
                    (a - b).abs() <= 2e-5 * scale,
                    "{arch:?} batch {batch}: fused {a} vs reference {b}"
                );
            }
        }
    }
}
