//! Networks: parameter counts, gradients against finite differences, determinism.

use railforce::learn::neural::{Architecture, NetConfig, Network};

fn config(architecture: Architecture, channels: usize, outputs: usize, dropout: f32) -> NetConfig {
    NetConfig {
        quantiles: None,
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
    // assets/docs/learning.md §3: 462 + 42 + 2816 + 256 + 24000 + 2624 + 520 + 9 = 30 729.
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

/// The hand-written engine against burn's autodiff (`cargo test --features burn`): the same
/// network as burn modules, the same weights, inputs and dropout masks.
#[cfg(feature = "burn")]
mod against_burn {
    use super::{config, data};
    use burn::tensor::Device;
    use railforce::learn::burn::BurnNet;
    use railforce::learn::neural::{Adam, Architecture, Network};
    use railforce::learn::train::{GradientEngine, Stepper};

    const ALL: [Architecture; 4] = [
        Architecture::CnnBiLstm,
        Architecture::Cnn,
        Architecture::BiLstm,
        Architecture::Gru,
    ];

    /// A network with every weight random, batch-norm scales and shifts away from 1 and 0,
    /// and running statistics away from their initial values.
    fn random_net(arch: Architecture, c: usize, o: usize) -> Network {
        let mut net = Network::new(config(arch, c, o, 0.2));
        for slot in net.params.slots.clone() {
            let bn = slot.name.starts_with("bn");
            for (k, i) in slot.range().enumerate() {
                let wobble = ((k as f32 + 1.0) * 0.917).sin();
                if slot.name.ends_with(".weight") && bn || slot.name.ends_with("running_var") {
                    net.params.value[i] = 1.0 + 0.3 * wobble;
                } else if bn {
                    net.params.value[i] = 0.2 * wobble;
                }
            }
        }
        net
    }

    /// `max |a − b| ≤ tol · max(max |a|, floor)` per slot; returns the worst relative error.
    fn compare(what: &str, net: &Network, a: &[f32], b: &[f32], tol: f32, floor: f32) -> f32 {
        let mut worst = 0.0f32;
        for slot in &net.params.slots {
            let r = slot.range();
            let scale = a[r.clone()].iter().fold(floor, |m, v| m.max(v.abs()));
            let err = a[r.clone()]
                .iter()
                .zip(&b[r])
                .fold(0.0f32, |m, (x, y)| m.max((x - y).abs()));
            assert!(
                err <= tol * scale,
                "{what} of {}: engine and burn differ by {err} (scale {scale})",
                slot.name
            );
            worst = worst.max(err / scale);
        }
        worst
    }

    #[test]
    fn every_weight_gradient_equals_burns_autodiff() {
        let device = Device::flex();
        for arch in ALL {
            let (batch, c, o) = (7, 5, 2);
            let mut net = random_net(arch, c, o);
            let (x, y) = data(batch, c, o);
            let before = net.params.value.clone();
            // The engine: training forward (dropout on, batch statistics), backward of the MSE.
            net.reseed_dropout(42);
            let mut scratch = Vec::new();
            let loss = Stepper::new(GradientEngine::Fused, &net.config)
                .unwrap()
                .step(&mut net, &x, &y, batch, &mut scratch)
                .unwrap();
            let engine_grad = net.params.grad.clone();
            let engine_stats = net.params.value.clone();
            // burn: the same weights and the same dropout masks.
            net.params.value = before;
            net.reseed_dropout(42);
            let mut module = BurnNet::new(&net.config, &device);
            let step_loss = module.gradients(&mut net, &x, &y, batch, &device).unwrap();
            assert!(
                (step_loss - loss).abs() <= 1e-5 * loss,
                "{arch:?}: loss {} vs {loss}",
                step_loss
            );
            let g = compare("gradient", &net, &engine_grad, &net.params.grad, 2e-4, 1e-6);
            // Running statistics (the only values a training step changes) agree as well.
            let s = compare("value", &net, &engine_stats, &net.params.value, 1e-5, 1e-3);
            println!("{arch:?}: worst relative gradient error {g:.1e}, statistics {s:.1e}");
        }
    }

    #[test]
    fn burns_evaluation_equals_the_engines() {
        let device = Device::flex();
        for arch in ALL {
            let (c, o) = (6, 2);
            let mut net = random_net(arch, c, o);
            let (x, _) = data(9, c, o);
            let engine = net.predict(&x, 9);
            let mut module = BurnNet::new(&net.config, &device);
            module.load(&net, &device);
            let burn = module.predict(&x, 9, 20, &device).unwrap();
            // Inputs that are not whole windows are refused, not a panic.
            assert!(module.predict(&x, 0, 20, &device).is_err());
            assert!(module.predict(&x[..100], 9, 20, &device).is_err());
            let scale = engine.iter().fold(1e-3f32, |m, v| m.max(v.abs()));
            for (a, b) in engine.iter().zip(&burn) {
                assert!((a - b).abs() <= 1e-5 * scale, "{arch:?}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn training_steps_follow_the_same_trajectory() {
        // Ten Adam steps from the same start, gradients by each engine: the weights stay
        // together (float rounding only), so burn training is the engine's algorithm.
        for arch in ALL {
            let (batch, c, o) = (8, 4, 1);
            let (x, y) = data(batch, c, o);
            let mut fused = random_net(arch, c, o);
            let mut viaburn = random_net(arch, c, o);
            // The trainer's own steppers, as `train --engine fused|burn-cpu` runs them.
            let mut by_engine = Stepper::new(GradientEngine::Fused, &fused.config).unwrap();
            let mut by_burn = Stepper::new(GradientEngine::BurnCpu, &viaburn.config).unwrap();
            let (mut a1, mut a2) = (
                Adam::new(fused.params.value.len(), 1e-3),
                Adam::new(viaburn.params.value.len(), 1e-3),
            );
            let mut scratch = Vec::new();
            for step in 0..10 {
                fused.reseed_dropout(step);
                by_engine
                    .step(&mut fused, &x, &y, batch, &mut scratch)
                    .unwrap();
                a1.step(&mut fused.params);
                viaburn.reseed_dropout(step);
                by_burn
                    .step(&mut viaburn, &x, &y, batch, &mut scratch)
                    .unwrap();
                a2.step(&mut viaburn.params);
            }
            // Adam's step is ±lr wherever a gradient is near zero, so rounding can flip a few
            // single steps: compare the whole movement, not single weights.
            let norm = |v: &mut dyn Iterator<Item = f32>| {
                v.map(|d| f64::from(d).powi(2)).sum::<f64>().sqrt()
            };
            let start = random_net(arch, c, o).params.value;
            let moved = norm(&mut fused.params.value.iter().zip(&start).map(|(a, b)| a - b));
            let apart = norm(
                &mut fused
                    .params
                    .value
                    .iter()
                    .zip(&viaburn.params.value)
                    .map(|(a, b)| a - b),
            );
            println!("{arch:?}: moved {moved:.3e}, apart {apart:.3e}");
            assert!(
                apart <= 0.01 * moved,
                "{arch:?}: after 10 steps the weights moved {moved} and are {apart} apart"
            );
        }
    }
}
