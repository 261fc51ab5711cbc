// An orbit camera around the tank (viewer/render/camera.h): yaw and pitch on a
// sphere around a target, distance for zoom, and the ground-plane axes that
// player movement is relative to, so "forward" is always away from the viewer.

export type Vec3 = [number, number, number];
export type Mat4 = Float32Array;  // column-major, as WebGL takes it

const FOV = Math.PI / 4;  // across the canvas's narrower side
const ORBIT_RADIANS_PER_PIXEL = 0.005;
const MAX_PITCH = 1.5;  // just short of straight down, where lookAt degenerates
export const ZOOM_PER_STEP = 0.9;  // the distance's factor per wheel step (or its worth of a pinch)

const sub = (a: Vec3, b: Vec3): Vec3 => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const dot = (a: Vec3, b: Vec3): number => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a: Vec3, b: Vec3): Vec3 => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
export const normalize = (a: Vec3): Vec3 => {
  const l = Math.hypot(a[0], a[1], a[2]);
  return l > 0 ? [a[0] / l, a[1] / l, a[2] / l] : [0, 0, 0];
};

function multiply(a: Mat4, b: Mat4): Mat4 {
  const out = new Float32Array(16);
  for (let c = 0; c < 4; ++c)
    for (let r = 0; r < 4; ++r) {
      let s = 0;
      for (let k = 0; k < 4; ++k) s += a[k * 4 + r] * b[c * 4 + k];
      out[c * 4 + r] = s;
    }
  return out;
}

function perspective(fovY: number, aspect: number, near: number, far: number): Mat4 {
  const f = 1 / Math.tan(fovY / 2);
  return new Float32Array([f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) / (near - far), -1, 0, 0,
                           (2 * far * near) / (near - far), 0]);
}

function lookAt(eye: Vec3, target: Vec3, up: Vec3): Mat4 {
  const f = normalize(sub(target, eye));
  const s = normalize(cross(f, up));
  const u = cross(s, f);
  return new Float32Array([s[0], u[0], -f[0], 0, s[1], u[1], -f[1], 0, s[2], u[2], -f[2], 0, -dot(s, eye),
                           -dot(u, eye), dot(f, eye), 1]);
}

// The radius in pixels of a sphere of `radius` at `centre`, on a viewport
// `heightPx` tall (viewer/render/math.h): row 1 of a perspective times a
// look-at is the focal length times the camera's up axis, row 3 the depth.
export function radiusOnScreen(viewProj: Mat4, centre: Vec3, radius: number, heightPx: number): number {
  const m = viewProj;  // column-major: m[col * 4 + row]
  const depth = m[3] * centre[0] + m[7] * centre[1] + m[11] * centre[2] + m[15];
  const focal = Math.hypot(m[1], m[5], m[9]);
  return depth > 0 ? (radius * focal * 0.5 * heightPx) / depth : 0;
}

// How much the own sphere's ring grows its radius: `grow`, or more where the
// sphere is small on screen, so that the ring reaches `minPx` (viewer/render/math.h).
export function outlineGrow(radiusPx: number, minPx: number, grow: number): number {
  return radiusPx > 0 ? Math.max(grow, minPx / radiusPx) : grow;
}

export class OrbitCamera {
  private target: Vec3 = [0, 20, 0];
  private yaw = 0;  // radians around +y; 0 looks along -z
  private pitch = 0.35;  // radians above the horizon
  private distance = 90;
  private minDistance = 2;
  private maxDistance = 400;

  // Frames the whole tank from slightly above, at any aspect ratio, aiming a
  // little below its centre where the pile sits.
  frame(min: Vec3, max: Vec3): void {
    const size = sub(max, min);
    this.target = [min[0] + 0.5 * size[0], min[1] + 0.45 * size[1], min[2] + 0.5 * size[2]];
    const radius = 0.5 * Math.hypot(size[0], size[1], size[2]);
    this.distance = radius / Math.sin(FOV / 2);
    this.minDistance = 0.05 * radius;
    this.maxDistance = 6 * radius;
    this.yaw = 0;
    this.pitch = 0.35;
  }

  orbit(dxPixels: number, dyPixels: number): void {
    this.yaw -= dxPixels * ORBIT_RADIANS_PER_PIXEL;
    this.pitch = Math.min(MAX_PITCH, Math.max(-MAX_PITCH, this.pitch + dyPixels * ORBIT_RADIANS_PER_PIXEL));
  }

  zoom(wheelSteps: number): void {
    this.distance = Math.min(this.maxDistance, Math.max(this.minDistance, this.distance * ZOOM_PER_STEP ** wheelSteps));
  }

  distanceToTarget(): number {
    return this.distance;
  }

  eye(): Vec3 {
    const c = Math.cos(this.pitch);
    return [this.target[0] - Math.sin(this.yaw) * c * this.distance, this.target[1] + Math.sin(this.pitch) * this.distance,
            this.target[2] + Math.cos(this.yaw) * c * this.distance];
  }

  viewProjection(canvasAspect: number): Mat4 {
    const aspect = canvasAspect > 0 && Number.isFinite(canvasAspect) ? canvasAspect : 1;  // a canvas of no size
    // A tall canvas (a phone held upright) widens the vertical field, so that
    // the horizontal one stays FOV and the tank still fits across.
    const fovY = aspect >= 1 ? FOV : 2 * Math.atan(Math.tan(FOV / 2) / aspect);
    return multiply(perspective(fovY, aspect, 0.1, this.distance + this.maxDistance), lookAt(this.eye(), this.target, [0, 1, 0]));
  }

  forwardOnGround(): Vec3 {
    return [Math.sin(this.yaw), 0, -Math.cos(this.yaw)];
  }

  rightOnGround(): Vec3 {
    return cross(this.forwardOnGround(), [0, 1, 0]);
  }
}
