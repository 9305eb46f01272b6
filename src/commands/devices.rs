//! `translucent devices`: the Vulkan devices, one line each.

use crate::error::Result;
use crate::vk;

pub(super) fn devices() -> Result<i32> {
    let list = vk::list_devices()?;
    let mut text = format!("{:<5} {:<40} {:<15} {:<9} {:<10} driver\n", "index", "name", "type", "api", "timestamps");
    for d in list {
        let usable = match &d.usable {
            Ok(()) => String::new(),
            Err(why) => format!("  (unusable: {why})"),
        };
        text += &format!(
            "{:<5} {:<40} {:<15} {:<9} {:<10} {}{usable}\n",
            d.index,
            d.name,
            d.type_name(),
            d.api_string(),
            if d.timestamps { "yes" } else { "no" },
            d.driver
        );
    }
    crate::error::write_stdout(&text)?;
    Ok(0)
}
