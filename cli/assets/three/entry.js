// The parts of three.js the lagrange viewer uses (cli/assets/viewer.js reads them as THREE.*).
// build.sh bundles this file with esbuild into three.bundle.min.js (an IIFE defining the global
// THREE): the page then needs no module loading and no network.
export {
  AmbientLight,
  ArrowHelper,
  AxesHelper,
  Box3,
  BoxGeometry,
  BufferAttribute,
  BufferGeometry,
  CapsuleGeometry,
  Color,
  CylinderGeometry,
  DirectionalLight,
  DoubleSide,
  FrontSide,
  GridHelper,
  Group,
  HemisphereLight,
  Matrix4,
  Mesh,
  MeshStandardMaterial,
  PerspectiveCamera,
  PlaneGeometry,
  Quaternion,
  REVISION,
  Scene,
  SphereGeometry,
  SRGBColorSpace,
  Vector3,
  WebGLRenderer,
} from 'three';
export { OrbitControls } from 'three/addons/controls/OrbitControls.js';
