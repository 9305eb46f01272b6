//! Interim (full version from the mesh branch).
pub struct Scope {
    pub name: String,
    pub begin_ns: f64,
    pub end_ns: f64,
}
pub struct ProfileReport {
    pub device: String,
    pub frames: Vec<Vec<Scope>>,
}
pub fn format_table(r: &ProfileReport) -> String {
    let mut s = format!("{}\n", r.device);
    for f in &r.frames {
        for sc in f {
            s += &format!("{} {:.3} ms\n", sc.name, (sc.end_ns - sc.begin_ns) / 1e6);
        }
    }
    s
}
pub fn chrome_trace_json(_r: &ProfileReport) -> String {
    String::new()
}
