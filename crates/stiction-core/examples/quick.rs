use stiction_core::reproduce::*;
fn main() {
    let args: Vec<f64> = std::env::args().skip(1).map(|a| a.parse().unwrap()).collect();
    let mut setup = PaperSetup::default();
    setup.aco.tau0 = args[0];
    setup.aco.local_search = args[1] as usize;
    setup.seeds = (1..=args[2] as u64).collect();
    let t = std::time::Instant::now();
    let r = reproduce_paper(&setup);
    for c in &r.cases {
        println!("true {} interval {:?} mean {:.4} worst {} inside {}/{} sec/run {:.6}", c.true_d, c.interval, c.mean, c.worst, c.inside, c.seeds.len(), c.seconds_per_run);
    }
    println!("total {:?}", t.elapsed());
}
