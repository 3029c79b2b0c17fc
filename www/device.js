// createEngine({ device }): sunlit's counter on a GPUDevice the caller already holds (e.g. a
// WebGPU renderer's). wgpu 30's WebGPU backend has no public way to wrap an existing GPUDevice
// (Device::as_webgpu goes the other way; its WebDevice constructor is private; Device::from_custom
// would mean re-implementing the whole backend). It does open its device through
// navigator.gpu.requestAdapter() and adapter.requestDevice(), looked up at call time, so for the
// one call that opens the engine, requestAdapter answers with an adapter whose requestDevice
// resolves to the given device (its features and limits are the device's). wgpu never destroys a
// device on drop, so sunlit leaves the caller's device alive; a loss of it is reported as sunlit's
// "device lost" error. The device's own uncapturederror handler is kept and still called.

/** Whether `device` looks like a GPUDevice. */
function isDevice(device) {
  return typeof GPUDevice !== 'undefined' ? device instanceof GPUDevice : !!device?.queue && typeof device.createBuffer === 'function';
}

/** Runs `open()` (which opens a wgpu device) so that it gets `device`; returns what it returns. */
export async function onDevice(device, open) {
  if (!isDevice(device)) throw new TypeError('createEngine: device must be a GPUDevice (from adapter.requestDevice())');
  const gpu = navigator.gpu;
  const info = device.adapterInfo ?? { vendor: '', architecture: '', device: '', description: '' };
  const proto = typeof GPUAdapter !== 'undefined' ? GPUAdapter.prototype : Object.prototype;
  const adapter = Object.create(proto, {
    features: { value: device.features },
    limits: { value: device.limits },
    info: { value: info },
    isFallbackAdapter: { value: false },
    requestDevice: { value: async () => device },
    requestAdapterInfo: { value: async () => info },
  });
  const earlier = device.onuncapturederror;
  let restored = false;
  const restore = () => {
    if (!restored) delete gpu.requestAdapter;
    restored = true;
  };
  Object.defineProperty(gpu, 'requestAdapter', {
    configurable: true,
    value: async () => {
      restore();
      return adapter;
    },
  });
  let result;
  try {
    result = await open();
  } finally {
    restore();
  }
  const ours = device.onuncapturederror;
  if (earlier && ours && ours !== earlier) {
    device.onuncapturederror = (event) => {
      ours.call(device, event);
      earlier.call(device, event);
    };
  }
  return result;
}
