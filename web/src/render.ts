// WebGL2 drawing: instanced spheres (a 12x12 UV mesh with smooth per-vertex
// normals), the tank's edges, white player spheres and an amber ring around
// this page's own, which shows through the balls that hide it.
//
// The balls' per-instance attributes are the snapshot's own arrays, uploaded
// as they arrive: the quantised uint16 positions of the two snapshots a frame
// lies between, and one kind byte per ball. The vertex shader blends the two,
// dequantises over the tank and looks up radius and colour by kind, so no
// per-ball work is done in JavaScript and no matrix exists per ball.

import { outlineGrow, radiusOnScreen, type Mat4, type Vec3 } from './camera';
import type { Pair, Player } from './snapshots';

export interface BallKind {
  diameter: number;
  rgb: [number, number, number];
}

const MAX_KINDS = 16;  // the shader's table; Welcome lists 3
const PLAYER_RADIUS = 0.5;  // kPlayerDiameter / 2 (common/tank.h)
const OUTLINE_GROW = 1.35;
const OUTLINE_MIN_PX = 8;  // CSS pixels: the ring's outer radius at least, so that a distant sphere is found
const OUTLINE_COLOUR: Vec3 = [1.0, 0.72, 0.1];
const HIDDEN_ALPHA = 0.8;  // the own sphere's amber over the balls in front of it
// The hidden pass takes its depth from a sphere a tenth larger than the own one: just in front of its
// surface, so that where the sphere is in view, the amber never ties with it in the depth test.
const HIDDEN_DEPTH_GROW = 1.1;
const CLEAR: [number, number, number] = [0.055, 0.066, 0.09];

// One fixed light from above and in front of the default camera, plus ambient so
// that the unlit side of a ball still shows its colour.
const FRAGMENT = `#version 300 es
precision mediump float;
in vec3 v_normal;
in vec3 v_colour;
uniform bool u_unlit;
out vec4 frag_colour;
const vec3 kLightDir = normalize(vec3(0.35, 0.85, 0.45));
const float kAmbient = 0.28;
void main() {
  float lambert = max(dot(normalize(v_normal), kLightDir), 0.0);
  float light = u_unlit ? 1.0 : kAmbient + (1.0 - kAmbient) * lambert;
  frag_colour = vec4(v_colour * light, 1.0);
}`;

const BALL_VERTEX = `#version 300 es
layout(location = 0) in vec3 a_unit;
layout(location = 1) in vec3 i_from;  // quantised, 0 .. 65535 per axis
layout(location = 2) in vec3 i_to;
layout(location = 3) in float i_kind;
uniform mat4 u_view_proj;
uniform vec3 u_tank_min;
uniform vec3 u_quantum;  // tank size / 65535
uniform float u_alpha;
uniform vec4 u_kinds[${MAX_KINDS}];  // rgb, radius
out vec3 v_normal;
out vec3 v_colour;
void main() {
  vec4 kind = u_kinds[int(i_kind)];
  vec3 centre = u_tank_min + mix(i_from, i_to, u_alpha) * u_quantum;
  v_normal = a_unit;
  v_colour = kind.rgb;
  gl_Position = u_view_proj * vec4(centre + a_unit * kind.w, 1.0);
}`;

const PLAYER_VERTEX = `#version 300 es
layout(location = 0) in vec3 a_unit;
layout(location = 1) in vec3 i_centre;
uniform mat4 u_view_proj;
uniform float u_radius;
uniform float u_depth_radius;
uniform vec3 u_colour;
out vec3 v_normal;
out vec3 v_colour;
void main() {
  v_normal = a_unit;
  v_colour = u_colour;
  gl_Position = u_view_proj * vec4(i_centre + a_unit * u_radius, 1.0);
  // The hidden pass: the ring's size at the sphere's own depth, so that what hides the sphere turns amber.
  if (u_depth_radius != u_radius) {
    vec4 at = u_view_proj * vec4(i_centre + a_unit * u_depth_radius, 1.0);
    gl_Position.z = at.z / at.w * gl_Position.w;
  }
}`;

// Blended over the scene so the lines stay faint against balls and background.
const LINE_VERTEX = `#version 300 es
layout(location = 0) in vec3 a_pos;
uniform mat4 u_view_proj;
void main() { gl_Position = u_view_proj * vec4(a_pos, 1.0); }`;
const LINE_FRAGMENT = `#version 300 es
precision mediump float;
out vec4 frag_colour;
void main() { frag_colour = vec4(0.75, 0.82, 0.95, 0.35); }`;

// (v + 1) rings of (u + 1) vertices, the seam column repeated; unit vectors are
// positions and normals at once (viewer/render/sphere_mesh.cpp).
function uvSphere(segmentsU: number, segmentsV: number): { vertices: Float32Array; indices: Uint16Array } {
  const vertices: number[] = [];
  for (let j = 0; j <= segmentsV; ++j) {
    const theta = (Math.PI * j) / segmentsV;
    for (let i = 0; i <= segmentsU; ++i) {
      const phi = (2 * Math.PI * i) / segmentsU;
      vertices.push(Math.sin(theta) * Math.cos(phi), Math.cos(theta), -Math.sin(theta) * Math.sin(phi));
    }
  }
  const ring = segmentsU + 1;
  const indices: number[] = [];
  for (let j = 0; j < segmentsV; ++j)
    for (let i = 0; i < segmentsU; ++i) {
      const a = j * ring + i;
      const b = a + ring;
      if (j !== 0) indices.push(a, b, a + 1);
      if (j !== segmentsV - 1) indices.push(a + 1, b, b + 1);
    }
  return { vertices: new Float32Array(vertices), indices: new Uint16Array(indices) };
}

function compile(gl: WebGL2RenderingContext, vertex: string, fragment: string): WebGLProgram {
  const program = gl.createProgram()!;
  for (const [type, source] of [[gl.VERTEX_SHADER, vertex], [gl.FRAGMENT_SHADER, fragment]] as const) {
    const shader = gl.createShader(type)!;
    gl.shaderSource(shader, source);
    gl.compileShader(shader);
    if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) throw new Error(`shader: ${gl.getShaderInfoLog(shader)}`);
    gl.attachShader(program, shader);
  }
  gl.linkProgram(program);
  if (!gl.getProgramParameter(program, gl.LINK_STATUS)) throw new Error(`program: ${gl.getProgramInfoLog(program)}`);
  return program;
}

function uniforms(gl: WebGL2RenderingContext, program: WebGLProgram, names: string[]): Record<string, WebGLUniformLocation> {
  const out: Record<string, WebGLUniformLocation> = {};
  for (const n of names) out[n] = gl.getUniformLocation(program, n)!;
  return out;
}

export class Renderer {
  private readonly balls: WebGLProgram;
  private readonly players: WebGLProgram;
  private readonly lines: WebGLProgram;
  private readonly ballU: Record<string, WebGLUniformLocation>;
  private readonly playerU: Record<string, WebGLUniformLocation>;
  private readonly lineU: Record<string, WebGLUniformLocation>;
  private readonly ballVao: WebGLVertexArrayObject;
  private readonly playerVao: WebGLVertexArrayObject;
  private readonly lineVao: WebGLVertexArrayObject;
  private readonly fromBuf: WebGLBuffer;
  private readonly toBuf: WebGLBuffer;
  private readonly kindBuf: WebGLBuffer;
  private readonly playerBuf: WebGLBuffer;
  private readonly lineBuf: WebGLBuffer;
  private readonly indexCount: number;
  private uploaded: { from: unknown; to: unknown; kinds: unknown } = { from: null, to: null, kinds: null };
  private kindTable = new Float32Array(4 * MAX_KINDS);
  private tankKey = '';

  constructor(private readonly gl: WebGL2RenderingContext) {
    this.balls = compile(gl, BALL_VERTEX, FRAGMENT);
    this.players = compile(gl, PLAYER_VERTEX, FRAGMENT);
    this.lines = compile(gl, LINE_VERTEX, LINE_FRAGMENT);
    this.ballU = uniforms(gl, this.balls, ['u_view_proj', 'u_tank_min', 'u_quantum', 'u_alpha', 'u_kinds', 'u_unlit']);
    this.playerU = uniforms(gl, this.players, ['u_view_proj', 'u_radius', 'u_depth_radius', 'u_colour', 'u_unlit']);
    this.lineU = uniforms(gl, this.lines, ['u_view_proj']);

    const mesh = uvSphere(12, 12);
    this.indexCount = mesh.indices.length;
    const meshBuf = gl.createBuffer()!;
    gl.bindBuffer(gl.ARRAY_BUFFER, meshBuf);
    gl.bufferData(gl.ARRAY_BUFFER, mesh.vertices, gl.STATIC_DRAW);
    const indexBuf = gl.createBuffer()!;
    this.fromBuf = gl.createBuffer()!;
    this.toBuf = gl.createBuffer()!;
    this.kindBuf = gl.createBuffer()!;
    this.playerBuf = gl.createBuffer()!;
    this.lineBuf = gl.createBuffer()!;

    const withMesh = (): WebGLVertexArrayObject => {
      const vao = gl.createVertexArray()!;
      gl.bindVertexArray(vao);
      gl.bindBuffer(gl.ARRAY_BUFFER, meshBuf);
      gl.enableVertexAttribArray(0);
      gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 12, 0);
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, indexBuf);
      return vao;
    };
    const instanced = (location: number, buffer: WebGLBuffer, size: number, type: number, stride: number): void => {
      gl.bindBuffer(gl.ARRAY_BUFFER, buffer);
      gl.enableVertexAttribArray(location);
      gl.vertexAttribPointer(location, size, type, false, stride, 0);  // integers read as floats, not normalised
      gl.vertexAttribDivisor(location, 1);
    };
    this.ballVao = withMesh();
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, mesh.indices, gl.STATIC_DRAW);
    instanced(1, this.fromBuf, 3, gl.UNSIGNED_SHORT, 6);
    instanced(2, this.toBuf, 3, gl.UNSIGNED_SHORT, 6);
    instanced(3, this.kindBuf, 1, gl.UNSIGNED_BYTE, 1);
    this.playerVao = withMesh();
    instanced(1, this.playerBuf, 3, gl.FLOAT, 12);
    this.lineVao = gl.createVertexArray()!;
    gl.bindVertexArray(this.lineVao);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.lineBuf);
    gl.enableVertexAttribArray(0);
    gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 12, 0);
    gl.bindVertexArray(null);

    gl.enable(gl.DEPTH_TEST);
    gl.enable(gl.CULL_FACE);
    gl.clearColor(CLEAR[0], CLEAR[1], CLEAR[2], 1);
  }

  setKinds(kinds: BallKind[]): void {
    this.kindTable.fill(0);
    kinds.slice(0, MAX_KINDS).forEach((k, i) => this.kindTable.set([k.rgb[0] / 255, k.rgb[1] / 255, k.rgb[2] / 255, 0.5 * k.diameter], 4 * i));
  }

  // Draws one frame. ownIndex: the page's player in `players`, or -1.
  draw(viewProj: Mat4, pair: Pair | null, players: Player[], ownIndex: number, showTank: boolean): void {
    const gl = this.gl;
    gl.viewport(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    if (!pair) return;
    const to = pair.to;

    if (to.ballCount > 0) {
      this.upload(pair);
      gl.useProgram(this.balls);
      gl.uniformMatrix4fv(this.ballU.u_view_proj, false, viewProj);
      gl.uniform3fv(this.ballU.u_tank_min, to.tankMin);
      gl.uniform3fv(this.ballU.u_quantum, to.tankMax.map((hi, a) => (hi - to.tankMin[a]) / 65535));
      gl.uniform1f(this.ballU.u_alpha, pair.alpha);
      gl.uniform4fv(this.ballU.u_kinds, this.kindTable);
      gl.uniform1i(this.ballU.u_unlit, 0);
      gl.bindVertexArray(this.ballVao);
      gl.drawElementsInstanced(gl.TRIANGLES, this.indexCount, gl.UNSIGNED_SHORT, 0, to.ballCount);
    }

    if (players.length) {
      const centres = new Float32Array(players.flatMap((p) => p.pos));
      gl.bindBuffer(gl.ARRAY_BUFFER, this.playerBuf);
      gl.bufferData(gl.ARRAY_BUFFER, centres, gl.DYNAMIC_DRAW);
      gl.useProgram(this.players);
      gl.uniformMatrix4fv(this.playerU.u_view_proj, false, viewProj);
      gl.bindVertexArray(this.playerVao);
      gl.uniform1f(this.playerU.u_radius, PLAYER_RADIUS);
      gl.uniform1f(this.playerU.u_depth_radius, PLAYER_RADIUS);
      gl.uniform3fv(this.playerU.u_colour, [1, 1, 1]);
      gl.uniform1i(this.playerU.u_unlit, 0);
      gl.drawElementsInstanced(gl.TRIANGLES, this.indexCount, gl.UNSIGNED_SHORT, 0, players.length);
      if (ownIndex >= 0) {
        // The inside of a larger, unlit sphere: a ring around the silhouette.
        const own = players[ownIndex].pos;
        // Device pixels per CSS pixel of the drawing buffer, which the browser may keep smaller than asked.
        const scale = gl.drawingBufferHeight / Math.max(1, (gl.canvas as HTMLCanvasElement).clientHeight);
        const grow = outlineGrow(radiusOnScreen(viewProj, own, PLAYER_RADIUS, gl.drawingBufferHeight),
                                 OUTLINE_MIN_PX * scale, OUTLINE_GROW);
        gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(own), gl.DYNAMIC_DRAW);
        gl.uniform1f(this.playerU.u_radius, PLAYER_RADIUS * grow);
        gl.uniform1f(this.playerU.u_depth_radius, PLAYER_RADIUS * grow);
        gl.uniform3fv(this.playerU.u_colour, OUTLINE_COLOUR);
        gl.uniform1i(this.playerU.u_unlit, 1);
        gl.cullFace(gl.FRONT);
        gl.drawElementsInstanced(gl.TRIANGLES, this.indexCount, gl.UNSIGNED_SHORT, 0, 1);
        gl.cullFace(gl.BACK);
        // Where balls hide it (the sphere starts amid the pour), a disc of the ring's size at the
        // sphere's own depth, amber and blended over them: only the depth test's GREATER passes,
        // so what is in view stays as drawn.
        gl.uniform1f(this.playerU.u_depth_radius, PLAYER_RADIUS * HIDDEN_DEPTH_GROW);
        gl.depthFunc(gl.GREATER);
        gl.depthMask(false);
        gl.enable(gl.BLEND);
        gl.blendColor(0, 0, 0, HIDDEN_ALPHA);
        gl.blendFunc(gl.CONSTANT_ALPHA, gl.ONE_MINUS_CONSTANT_ALPHA);
        gl.drawElementsInstanced(gl.TRIANGLES, this.indexCount, gl.UNSIGNED_SHORT, 0, 1);
        gl.disable(gl.BLEND);
        gl.depthMask(true);
        gl.depthFunc(gl.LESS);
      }
    }

    if (showTank) {
      this.setTank(to.tankMin, to.tankMax);
      gl.useProgram(this.lines);
      gl.uniformMatrix4fv(this.lineU.u_view_proj, false, viewProj);
      gl.bindVertexArray(this.lineVao);
      gl.enable(gl.BLEND);
      gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
      gl.drawArrays(gl.LINES, 0, 24);
      gl.disable(gl.BLEND);
    }
    gl.bindVertexArray(null);
  }

  // The snapshot arrays go to the GPU only when the pair changes, not every frame.
  private upload(pair: Pair): void {
    const gl = this.gl;
    const { from, to } = pair;
    if (this.uploaded.to !== to.quantised) {
      gl.bindBuffer(gl.ARRAY_BUFFER, this.toBuf);
      gl.bufferData(gl.ARRAY_BUFFER, to.quantised, gl.DYNAMIC_DRAW);
    }
    if (this.uploaded.from !== from.quantised || this.uploaded.to !== to.quantised) {
      let q = from.quantised;
      // Balls new in `to` have no earlier position: they appear where they are.
      if (from.ballCount < to.ballCount) {
        q = new Uint16Array(3 * to.ballCount);
        q.set(from.quantised);
        q.set(to.quantised.subarray(3 * from.ballCount), 3 * from.ballCount);
      }
      gl.bindBuffer(gl.ARRAY_BUFFER, this.fromBuf);
      gl.bufferData(gl.ARRAY_BUFFER, q, gl.DYNAMIC_DRAW);
    }
    if (this.uploaded.kinds !== to.kinds) {
      gl.bindBuffer(gl.ARRAY_BUFFER, this.kindBuf);
      gl.bufferData(gl.ARRAY_BUFFER, to.kinds, gl.DYNAMIC_DRAW);
    }
    this.uploaded = { from: from.quantised, to: to.quantised, kinds: to.kinds };
  }

  // Corner c has x from bit 0, y from bit 1, z from bit 2; an edge joins two corners one bit apart.
  private setTank(min: Vec3, max: Vec3): void {
    const key = `${min} ${max}`;
    if (key === this.tankKey) return;
    this.tankKey = key;
    const corner = (c: number): number[] => [c & 1 ? max[0] : min[0], c & 2 ? max[1] : min[1], c & 4 ? max[2] : min[2]];
    const lines: number[] = [];
    for (let c = 0; c < 8; ++c)
      for (let bit = 1; bit < 8; bit <<= 1) if (!(c & bit)) lines.push(...corner(c), ...corner(c | bit));
    this.gl.bindBuffer(this.gl.ARRAY_BUFFER, this.lineBuf);
    this.gl.bufferData(this.gl.ARRAY_BUFFER, new Float32Array(lines), this.gl.STATIC_DRAW);
  }
}
