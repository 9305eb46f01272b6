//! Instance, validation messenger, physical-device choice, logical device, queue and allocator.
//!
//! Everything that must be destroyed in a fixed order lives in [`Shared`]; resources hold an
//! `Arc<Shared>`, so the device outlives every buffer and image made from it, and the messenger
//! outlives the device (the layer reports leaked objects while the device is destroyed).

use std::ffi::{c_void, CStr, CString};
use std::mem::ManuallyDrop;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

use super::guard::Guard;
use crate::error::Result;
use crate::{bad_input, runtime};

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// Counts of validation messages, shared with the debug callback. Kept alive by an `Arc` beyond the
/// instance so that messages emitted while the instance is destroyed are still counted.
#[derive(Debug, Default)]
pub struct ValidationCounts {
    pub warnings: AtomicU32,
    pub errors: AtomicU32,
}

impl ValidationCounts {
    pub fn total(&self) -> u32 {
        self.warnings.load(Ordering::SeqCst) + self.errors.load(Ordering::SeqCst)
    }

    /// A command's exit code: 1 (with a summary on stderr) when the validation layer reported
    /// anything, else 0.
    pub fn exit_code(&self, validating: bool) -> i32 {
        let (w, e) = (self.warnings.load(Ordering::SeqCst), self.errors.load(Ordering::SeqCst));
        if w + e > 0 {
            crate::note!("error: validation reported {e} error(s) and {w} warning(s)");
            return 1;
        }
        if validating {
            log::info!("validation: no messages");
        }
        0
    }
}

#[derive(Clone, Debug, Default)]
pub struct ContextOptions {
    /// Enable `VK_LAYER_KHRONOS_validation` with synchronization validation.
    pub validation: bool,
    /// `--device`: an index into the device list or a case-insensitive substring of the name.
    pub device: Option<String>,
}

/// A physical device as the `devices` command lists it.
#[derive(Clone, Debug)]
pub struct DeviceInfo {
    pub index: usize,
    pub name: String,
    pub device_type: vk::PhysicalDeviceType,
    pub api_version: u32,
    pub driver: String,
    pub timestamps: bool,
    pub usable: std::result::Result<(), String>,
}

impl DeviceInfo {
    pub fn type_name(&self) -> &'static str {
        match self.device_type {
            vk::PhysicalDeviceType::DISCRETE_GPU => "discrete GPU",
            vk::PhysicalDeviceType::INTEGRATED_GPU => "integrated GPU",
            vk::PhysicalDeviceType::VIRTUAL_GPU => "virtual GPU",
            vk::PhysicalDeviceType::CPU => "CPU",
            _ => "other",
        }
    }

    pub fn api_string(&self) -> String {
        let v = self.api_version;
        format!("{}.{}.{}", vk::api_version_major(v), vk::api_version_minor(v), vk::api_version_patch(v))
    }

    /// Preference when no `--device` is given: discrete > integrated > virtual > CPU.
    fn rank(&self) -> u32 {
        match self.device_type {
            vk::PhysicalDeviceType::DISCRETE_GPU => 4,
            vk::PhysicalDeviceType::INTEGRATED_GPU => 3,
            vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
            vk::PhysicalDeviceType::CPU => 1,
            _ => 0,
        }
    }
}

/// The debug-utils loader and the messenger made with it.
type Messenger = (ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT);

/// Objects destroyed together, in reverse creation order, when the last owner drops.
pub struct Shared {
    pub(crate) entry: ash::Entry,
    pub(crate) instance: ash::Instance,
    debug: Option<Messenger>,
    pub(crate) device: ash::Device,
    pub(crate) allocator: ManuallyDrop<Mutex<Allocator>>,
    /// Keeps the callback's user data alive until after `vkDestroyInstance`.
    _counts: Arc<ValidationCounts>,
}

impl Drop for Shared {
    fn drop(&mut self) {
        // SAFETY: the last owner is going away; nothing else can use these handles.
        unsafe {
            let _ = self.device.device_wait_idle();
            ManuallyDrop::drop(&mut self.allocator);
            self.device.destroy_device(None);
            if let Some((loader, messenger)) = self.debug.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

/// The Vulkan device the renderer runs on, with its one graphics + compute queue.
pub struct Context {
    pub(crate) shared: Arc<Shared>,
    pub(crate) physical_device: vk::PhysicalDevice,
    pub(crate) queue_family: u32,
    pub(crate) queue: vk::Queue,
    pub properties: vk::PhysicalDeviceProperties,
    pub info: DeviceInfo,
    /// Bits of a timestamp that are valid on the queue; 0 means no timestamps.
    pub timestamp_valid_bits: u32,
    pub has_shader_int64: bool,
    /// Lanes of a subgroup (a SIMD group on llvmpipe, a warp or wave on a GPU).
    pub subgroup_size: u32,
    counts: Arc<ValidationCounts>,
    pub validation: bool,
    pub(crate) commands: super::submit::CommandsCell,
}

impl Drop for Context {
    fn drop(&mut self) {
        // Recording objects go first; `Shared` (device, messenger, instance) goes when its last
        // owner drops.
        let _ = self.wait_idle();
        self.commands.get_mut().destroy(&self.shared.device);
    }
}

unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: the layer passes valid pointers for the duration of the call; `user` is the
    // `ValidationCounts` kept alive by `Shared`/`Context`.
    let (message, id) = unsafe {
        let d = &*data;
        (
            d.message_as_c_str().map(|m| m.to_string_lossy().into_owned()).unwrap_or_default(),
            d.message_id_name_as_c_str().map(|m| m.to_string_lossy().into_owned()).unwrap_or_default(),
        )
    };
    let counts = unsafe { &*(user as *const ValidationCounts) };
    // The loader reports through the same messenger; its notices (e.g. "VK_INSTANCE_LAYERS defined")
    // are not validation findings. Best practices also flags the very extension we use to listen.
    let not_a_finding = (types == vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
        && !severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR))
        || id == "UNASSIGNED-BestPractices-vkCreateInstance-specialuse-extension-debugging";
    if not_a_finding {
        log::debug!("vulkan {types:?} [{id}]: {message}");
    } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        counts.errors.fetch_add(1, Ordering::SeqCst);
        // Straight to stderr, not through `log`: a finding must show whatever the logger setup
        // (tests have none).
        crate::note!("vulkan validation error [{id}]: {message}");
    } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING) {
        counts.warnings.fetch_add(1, Ordering::SeqCst);
        crate::note!("vulkan validation warning [{id}]: {message}");
    } else {
        log::debug!("vulkan {types:?} [{id}]: {message}");
    }
    vk::FALSE
}

fn load_entry() -> Result<ash::Entry> {
    // SAFETY: loading the system Vulkan loader; it is a plain shared library.
    unsafe { ash::Entry::load() }.map_err(|e| {
        runtime!("cannot load the Vulkan loader ({e}); install libvulkan1 and a driver (e.g. mesa-vulkan-drivers)")
    })
}

/// True when the user forced the validation layer from outside (`VK_INSTANCE_LAYERS`), so that we
/// still hook its messages into our counts.
fn layer_forced_from_environment() -> bool {
    std::env::var("VK_INSTANCE_LAYERS").map(|v| v.contains("VK_LAYER_KHRONOS_validation")).unwrap_or(false)
}

fn create_instance(
    entry: &ash::Entry,
    validation: bool,
    counts: &Arc<ValidationCounts>,
    window_extensions: &[*const std::ffi::c_char],
) -> Result<(ash::Instance, bool)> {
    // SAFETY: plain enumeration calls on a loaded entry.
    let layers = unsafe { entry.enumerate_instance_layer_properties() }
        .map_err(|e| runtime!("vkEnumerateInstanceLayerProperties: {e}"))?;
    let has_layer = layers.iter().any(|l| l.layer_name_as_c_str().ok() == Some(VALIDATION_LAYER));
    if validation && !has_layer {
        return Err(runtime!(
            "--validation: the layer VK_LAYER_KHRONOS_validation is not installed (Debian: apt-get install vulkan-validationlayers)"
        ));
    }
    let messenger_wanted = validation || (has_layer && layer_forced_from_environment());

    let app_name = CString::new("translucent").unwrap();
    let app = vk::ApplicationInfo::default()
        .application_name(&app_name)
        .application_version(1)
        .engine_name(&app_name)
        .api_version(vk::API_VERSION_1_3);

    let layer_names: Vec<*const i8> = if validation { vec![VALIDATION_LAYER.as_ptr()] } else { vec![] };
    let mut extension_names: Vec<*const i8> =
        if messenger_wanted { vec![ash::ext::debug_utils::NAME.as_ptr()] } else { vec![] };
    extension_names.extend_from_slice(window_extensions);

    let enabled_features = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
    let mut validation_features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&enabled_features);
    let mut messenger_info = messenger_create_info(counts);

    let mut create_info = vk::InstanceCreateInfo::default()
        .application_info(&app)
        .enabled_layer_names(&layer_names)
        .enabled_extension_names(&extension_names);
    if messenger_wanted {
        // Chained so that instance creation and destruction are validated and counted too.
        create_info = create_info.push_next(&mut messenger_info);
    }
    if validation {
        create_info = create_info.push_next(&mut validation_features);
    }
    // SAFETY: every pointer in create_info refers to locals that outlive the call.
    let instance = unsafe { entry.create_instance(&create_info, None) }.map_err(|e| match e {
        vk::Result::ERROR_INCOMPATIBLE_DRIVER => {
            runtime!("no Vulkan 1.3 driver found (vkCreateInstance: {e}); install mesa-vulkan-drivers for lavapipe")
        }
        e => runtime!("vkCreateInstance: {e}"),
    })?;
    Ok((instance, messenger_wanted))
}

fn messenger_create_info(counts: &Arc<ValidationCounts>) -> vk::DebugUtilsMessengerCreateInfoEXT<'static> {
    vk::DebugUtilsMessengerCreateInfoEXT::default()
        .message_severity(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR)
        .message_type(
            vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
        )
        .pfn_user_callback(Some(debug_callback))
        .user_data(Arc::as_ptr(counts) as *mut c_void)
}

/// Graphics + compute queue family, if the device has one.
fn find_queue_family(instance: &ash::Instance, pd: vk::PhysicalDevice) -> Option<(u32, u32)> {
    // SAFETY: valid physical device from this instance.
    let families = unsafe { instance.get_physical_device_queue_family_properties(pd) };
    families.iter().enumerate().find_map(|(i, f)| {
        f.queue_flags
            .contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE)
            .then_some((i as u32, f.timestamp_valid_bits))
    })
}

fn describe_devices(instance: &ash::Instance) -> Result<Vec<(vk::PhysicalDevice, DeviceInfo)>> {
    // SAFETY: enumeration and property queries on a valid instance.
    let pds =
        unsafe { instance.enumerate_physical_devices() }.map_err(|e| runtime!("vkEnumeratePhysicalDevices: {e}"))?;
    let mut out = Vec::new();
    for (index, pd) in pds.into_iter().enumerate() {
        let mut driver = vk::PhysicalDeviceDriverProperties::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver);
        unsafe { instance.get_physical_device_properties2(pd, &mut props2) };
        let props = props2.properties;
        let driver_name = format!(
            "{} {}",
            driver.driver_name_as_c_str().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default(),
            driver.driver_info_as_c_str().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()
        );
        let queue = find_queue_family(instance, pd);
        let timestamps = props.limits.timestamp_compute_and_graphics == vk::TRUE || queue.is_some_and(|q| q.1 > 0);
        let usable = if props.api_version < vk::API_VERSION_1_3 {
            Err("needs Vulkan 1.3".to_string())
        } else if queue.is_none() {
            Err("no queue with graphics and compute".to_string())
        } else {
            Ok(())
        };
        out.push((
            pd,
            DeviceInfo {
                index,
                name: props.device_name_as_c_str().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default(),
                device_type: props.device_type,
                api_version: props.api_version,
                driver: driver_name.trim().to_string(),
                timestamps,
                usable,
            },
        ));
    }
    Ok(out)
}

/// Lists the physical devices without creating a logical device (the `devices` command).
pub fn list_devices() -> Result<Vec<DeviceInfo>> {
    let entry = load_entry()?;
    let counts = Arc::new(ValidationCounts::default());
    let (instance, _) = create_instance(&entry, false, &counts, &[])?;
    let list = describe_devices(&instance);
    // SAFETY: nothing was created from this instance.
    unsafe { instance.destroy_instance(None) };
    Ok(list?.into_iter().map(|(_, info)| info).collect())
}

fn choose_device(
    devices: &[(vk::PhysicalDevice, DeviceInfo)],
    wanted: Option<&str>,
) -> Result<(vk::PhysicalDevice, DeviceInfo)> {
    let listing = || {
        devices
            .iter()
            .map(|(_, d)| format!("  {}: {} ({})", d.index, d.name, d.type_name()))
            .collect::<Vec<_>>()
            .join("\n")
    };
    if devices.is_empty() {
        return Err(runtime!("no Vulkan device found; install a driver (Debian: mesa-vulkan-drivers for lavapipe)"));
    }
    let chosen = match wanted {
        Some(w) => {
            if w.trim().parse::<i64>().is_ok_and(|i| i < 0) {
                return Err(bad_input!("--device {w}: an index is 0 or more (`translucent devices` lists them)"));
            }
            let found = match w.trim().parse::<usize>() {
                Ok(i) => devices.iter().find(|(_, d)| d.index == i),
                Err(_) => {
                    let w = w.to_lowercase();
                    devices.iter().find(|(_, d)| d.name.to_lowercase().contains(&w))
                }
            };
            found.ok_or_else(|| bad_input!("--device {w}: no such device; devices are:\n{}", listing()))?
        }
        None => devices
            .iter()
            .filter(|(_, d)| d.usable.is_ok())
            .max_by_key(|(_, d)| (d.rank(), std::cmp::Reverse(d.index)))
            .ok_or_else(|| runtime!("no usable Vulkan 1.3 device with a graphics+compute queue:\n{}", listing()))?,
    };
    if let Err(why) = &chosen.1.usable {
        return Err(bad_input!("--device: {} cannot be used: {why}", chosen.1.name));
    }
    Ok(chosen.clone())
}

impl Context {
    pub fn new(options: &ContextOptions) -> Result<Context> {
        Self::create(options, None)
    }

    /// A context that can present to windows of `display`: the surface extensions for that window
    /// system on the instance and VK_KHR_swapchain on the device (only `view` asks for them).
    pub fn for_window(options: &ContextOptions, display: raw_window_handle::RawDisplayHandle) -> Result<Context> {
        Self::create(options, Some(display))
    }

    fn create(options: &ContextOptions, display: Option<raw_window_handle::RawDisplayHandle>) -> Result<Context> {
        let entry = load_entry()?;
        let counts = Arc::new(ValidationCounts::default());
        let window_extensions = match display {
            Some(d) => ash_window::enumerate_required_extensions(d)
                .map_err(|e| runtime!("no Vulkan surface extensions for this window system: {e}"))?,
            None => &[],
        };
        let (instance, messenger_wanted) = create_instance(&entry, options.validation, &counts, window_extensions)?;
        // From here on, an early return drops the guards, which destroy what was made so far
        // (messenger, then instance); `create_device` defuses them once the context owns both.
        // SAFETY (cleanup): on an error path nothing else uses the instance.
        let instance = Guard::new(instance, |i: ash::Instance| unsafe { i.destroy_instance(None) });

        let debug = if messenger_wanted {
            let loader = ash::ext::debug_utils::Instance::new(&entry, &instance);
            // SAFETY: the create-info points to `counts`, which outlives the messenger.
            let messenger = unsafe { loader.create_debug_utils_messenger(&messenger_create_info(&counts), None) }
                .map_err(|e| runtime!("vkCreateDebugUtilsMessengerEXT: {e}"))?;
            Some((loader, messenger))
        } else {
            None
        };
        let debug = Guard::new(debug, |debug: Option<Messenger>| {
            if let Some((loader, m)) = debug {
                // SAFETY: error path; the messenger is not used afterwards.
                unsafe { loader.destroy_debug_utils_messenger(m, None) };
            }
        });

        let devices = describe_devices(&instance)?;
        let (pd, info) = choose_device(&devices, options.device.as_deref())?;
        let swapchain = display.is_some();
        Self::create_device(entry.clone(), instance, debug, pd, info, counts, options.validation, swapchain)
    }

    /// The logical device and what hangs off it. `instance` and `debug` are guarded: any error
    /// return destroys them, after the objects made here (the parameters drop last).
    #[allow(clippy::too_many_arguments)]
    fn create_device(
        entry: ash::Entry,
        instance: Guard<ash::Instance, impl FnOnce(ash::Instance)>,
        debug: Guard<Option<Messenger>, impl FnOnce(Option<Messenger>)>,
        pd: vk::PhysicalDevice,
        info: DeviceInfo,
        counts: Arc<ValidationCounts>,
        validation: bool,
        swapchain: bool,
    ) -> Result<Context> {
        let (queue_family, timestamp_valid_bits) = find_queue_family(&instance, pd).expect("checked by choose_device");
        // SAFETY: valid physical device.
        let properties = unsafe { instance.get_physical_device_properties(pd) };
        let mut subgroup = vk::PhysicalDeviceSubgroupProperties::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut subgroup);
        // SAFETY: as above; `subgroup` outlives the call.
        unsafe { instance.get_physical_device_properties2(pd, &mut props2) };
        let subgroup_size = subgroup.subgroup_size.max(1);

        // Check the features we rely on before asking for them, to name what is missing.
        let mut have13 = vk::PhysicalDeviceVulkan13Features::default();
        let mut have12 = vk::PhysicalDeviceVulkan12Features::default();
        let mut have = vk::PhysicalDeviceFeatures2::default().push_next(&mut have12).push_next(&mut have13);
        unsafe { instance.get_physical_device_features2(pd, &mut have) };
        let have10 = have.features;
        let mut missing = Vec::new();
        if have13.dynamic_rendering == vk::FALSE {
            missing.push("dynamicRendering");
        }
        if have13.synchronization2 == vk::FALSE {
            missing.push("synchronization2");
        }
        if have13.maintenance4 == vk::FALSE {
            // Optimised SPIR-V 1.6 declares work-group sizes with LocalSizeId, which needs it.
            missing.push("maintenance4");
        }
        if have12.vulkan_memory_model == vk::FALSE || have12.vulkan_memory_model_device_scope == vk::FALSE {
            // The tree's bottom-up pass hands data between invocations with acquire/release atomics.
            missing.push("vulkanMemoryModel");
        }
        if have12.host_query_reset == vk::FALSE {
            missing.push("hostQueryReset");
        }
        if have10.fragment_stores_and_atomics == vk::FALSE {
            // The shade pass's fragment shader writes its work counters (a storage buffer).
            missing.push("fragmentStoresAndAtomics");
        }
        if !missing.is_empty() {
            return Err(runtime!("device {} lacks required Vulkan features: {}", info.name, missing.join(", ")));
        }
        let has_shader_int64 = have10.shader_int64 == vk::TRUE;

        let features10 =
            vk::PhysicalDeviceFeatures::default().shader_int64(has_shader_int64).fragment_stores_and_atomics(true);
        let mut features12 = vk::PhysicalDeviceVulkan12Features::default()
            .host_query_reset(true)
            .vulkan_memory_model(true)
            .vulkan_memory_model_device_scope(true);
        let mut features13 = vk::PhysicalDeviceVulkan13Features::default()
            .dynamic_rendering(true)
            .synchronization2(true)
            .maintenance4(true);
        let priorities = [1.0f32];
        let queue_info =
            [vk::DeviceQueueCreateInfo::default().queue_family_index(queue_family).queue_priorities(&priorities)];
        let device_extensions: Vec<*const std::ffi::c_char> =
            if swapchain { vec![ash::khr::swapchain::NAME.as_ptr()] } else { vec![] };
        if swapchain {
            // SAFETY: valid physical device.
            let available = unsafe { instance.enumerate_device_extension_properties(pd) }.unwrap_or_default();
            if !available.iter().any(|e| e.extension_name_as_c_str().ok() == Some(ash::khr::swapchain::NAME)) {
                return Err(runtime!("device {} cannot present to a window (no VK_KHR_swapchain)", info.name));
            }
        }
        let device_info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_info)
            .enabled_extension_names(&device_extensions)
            .enabled_features(&features10)
            .push_next(&mut features12)
            .push_next(&mut features13);
        // SAFETY: create-info points to locals alive for the call.
        let device = unsafe { instance.create_device(pd, &device_info, None) }
            .map_err(|e| runtime!("vkCreateDevice on {}: {e}", info.name))?;
        // SAFETY (cleanup): on an error path nothing else uses the device.
        let device = Guard::new(device, |d: ash::Device| unsafe { d.destroy_device(None) });
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
        let commands = super::submit::Commands::new(&device, queue_family)?;
        let commands = Guard::new(commands, {
            let device = (*device).clone();
            move |mut c: super::submit::Commands| c.destroy(&device)
        });

        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: (*instance).clone(),
            device: (*device).clone(),
            physical_device: pd,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })
        .map_err(|e| runtime!("gpu-allocator: {e}"))?;

        // Everything exists: `Shared` and the context own it from here on.
        let commands = commands.defuse();
        let shared = Arc::new(Shared {
            entry,
            device: device.defuse(),
            debug: debug.defuse(),
            instance: instance.defuse(),
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            _counts: counts.clone(),
        });
        log::info!("device: {} ({}, {}, Vulkan {})", info.name, info.type_name(), info.driver, info.api_string());
        Ok(Context {
            shared,
            physical_device: pd,
            queue_family,
            queue,
            properties,
            info,
            timestamp_valid_bits,
            has_shader_int64,
            subgroup_size,
            counts,
            validation,
            commands: std::cell::RefCell::new(commands),
        })
    }

    pub(crate) fn device(&self) -> &ash::Device {
        &self.shared.device
    }

    pub fn limits(&self) -> &vk::PhysicalDeviceLimits {
        &self.properties.limits
    }

    /// What the driver allows for a 2D optimal-tiling image of `format` with `usage`
    /// (`vkGetPhysicalDeviceImageFormatProperties`): maximum extent, layers and resource size.
    /// `None` when the combination is not supported at all.
    pub fn image_format_properties(
        &self,
        format: vk::Format,
        usage: vk::ImageUsageFlags,
    ) -> Option<vk::ImageFormatProperties> {
        // SAFETY: valid physical device of this instance.
        unsafe {
            self.shared.instance.get_physical_device_image_format_properties(
                self.physical_device,
                format,
                vk::ImageType::TYPE_2D,
                vk::ImageTiling::OPTIMAL,
                usage,
                vk::ImageCreateFlags::empty(),
            )
        }
        .ok()
    }

    /// The size of the largest device-local memory heap, in bytes.
    pub fn largest_device_heap(&self) -> u64 {
        // SAFETY: valid physical device of this instance.
        let memory = unsafe { self.shared.instance.get_physical_device_memory_properties(self.physical_device) };
        memory.memory_heaps[..memory.memory_heap_count as usize]
            .iter()
            .filter(|h| h.flags.contains(vk::MemoryHeapFlags::DEVICE_LOCAL))
            .map(|h| h.size)
            .max()
            .unwrap_or(0)
    }

    /// Validation message counts; keep the `Arc` to read them after the context is dropped
    /// (leaks are reported while the device is destroyed).
    pub fn validation_counts(&self) -> Arc<ValidationCounts> {
        self.counts.clone()
    }

    pub fn wait_idle(&self) -> Result<()> {
        // SAFETY: valid device.
        unsafe { self.device().device_wait_idle() }.map_err(|e| runtime!("vkDeviceWaitIdle: {e}"))
    }
}

/// Deliberate misuse, so tests can prove that validation messages and leaks are caught.
#[doc(hidden)]
impl Context {
    /// Creates a buffer of size 0 (invalid usage) if the driver lets it through, and destroys it.
    pub fn debug_provoke_validation_error(&self) {
        let info = vk::BufferCreateInfo::default().size(0).usage(vk::BufferUsageFlags::STORAGE_BUFFER);
        // SAFETY: deliberately invalid create-info for the layer to report; the buffer, if any, is destroyed.
        if let Ok(b) = unsafe { self.device().create_buffer(&info, None) } {
            unsafe { self.device().destroy_buffer(b, None) };
        }
    }

    /// Creates a sampler and never destroys it: the layer reports it when the device is destroyed.
    pub fn debug_leak_object(&self) {
        let info = vk::SamplerCreateInfo::default();
        // SAFETY: valid create-info; leaking the handle is the point.
        let _ = unsafe { self.device().create_sampler(&info, None) };
    }
}
