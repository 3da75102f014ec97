// The parts of three.js the viewer uses, bundled by `scripts/build_viewer.sh` (esbuild) into
// vendor/three.bundle.min.js so the page needs no network. three.js: MIT, vendor/three.LICENSE.
export {
  AmbientLight,
  AnimationMixer,
  ArrowHelper,
  Box3,
  BufferAttribute,
  BufferGeometry,
  Color,
  DirectionalLight,
  HemisphereLight,
  LoopRepeat,
  Mesh,
  PerspectiveCamera,
  Points,
  PointsMaterial,
  Scene,
  SRGBColorSpace,
  Vector3,
  WebGLRenderer,
} from 'three';
export { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
export { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
