//! `railforce channels`: the columns a run of a vehicle records, as the recorder lists them.

use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct ChannelsArgs {
    /// Vehicle file (or a built-in name: c80, c80_empty).
    #[arg(long, default_value = "vehicles/c80.toml")]
    vehicle: PathBuf,
    /// Print the Markdown table of assets/docs/channels.md (number, name, unit, kind,
    /// meaning) instead of one `name<TAB>unit<TAB>meaning` line per channel.
    #[arg(long)]
    markdown: bool,
    /// Add the channels a run in a train records (`simulate --consist`): each coupler's
    /// force and angle.
    #[arg(long)]
    in_train: bool,
}

pub fn run(args: ChannelsArgs) -> Result<()> {
    let v = railforce::vehicle::Vehicle::load(&super::builtin::resolve(&args.vehicle)?)?;
    let list = railforce::sim::channels::channels_of(&v, args.in_train);
    if args.markdown {
        print!(
            "{}",
            railforce::sim::channels::markdown(
                &list,
                &railforce::sensors::label_channels(&v.label_wheel_name())
            )
        );
    } else {
        for c in &list {
            println!("{}\t{}\t{}", c.name, c.unit, c.meaning);
        }
    }
    Ok(())
}
