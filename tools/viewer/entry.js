// The parts of three.js that jourdain's 3-D view uses (src/jourdain/io/viewer/viewer.js), bundled
// by tools/build_viewer.sh into one IIFE script that defines the global JD3 (three.js itself
// ships ES modules only, which a page opened from file:// cannot import).
export {
  AmbientLight,
  BoxGeometry,
  BufferAttribute,
  BufferGeometry,
  Color,
  CylinderGeometry,
  DirectionalLight,
  DoubleSide,
  GridHelper,
  Group,
  HemisphereLight,
  LineBasicMaterial,
  LineSegments,
  Matrix4,
  Mesh,
  MeshStandardMaterial,
  PerspectiveCamera,
  Quaternion,
  REVISION,
  Scene,
  SphereGeometry,
  Vector3,
  WebGLRenderer,
} from "three";
export { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
