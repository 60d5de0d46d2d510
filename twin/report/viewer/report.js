// The report's 3D view: the virtual assembly's glTF animation, played in three.js; a click on
// a finding shows the parts it names. window.agileReport lets a headless browser step it
// frame by frame (cellctl plan --video).
(function () {
  "use strict";
  const canvas = document.getElementById("view");
  const caption = document.getElementById("caption");
  const errorBox = document.getElementById("viewer-error");
  const playButton = document.getElementById("play");
  const slider = document.getElementById("time");
  const clock = document.getElementById("clock");
  const data = JSON.parse(document.getElementById("report-data").textContent);

  function fail(message) {
    errorBox.hidden = false;
    errorBox.textContent = message;
    document.body.dataset.viewer = "failed";
  }

  let renderer;
  try {
    renderer = new THREE.WebGLRenderer({ canvas: canvas, antialias: true, preserveDrawingBuffer: true });
  } catch (e) {
    fail("No 3D view: this browser gives the page no WebGL. The tables below hold the whole plan.");
    return;
  }
  renderer.setPixelRatio(1);
  renderer.setSize(canvas.width, canvas.height, false);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf3f4f6);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x80909f, 0.85));
  const sun = new THREE.DirectionalLight(0xffffff, 0.65);
  sun.position.set(1, 2, 1.5);
  scene.add(sun);
  const camera = new THREE.PerspectiveCamera(40, canvas.width / canvas.height, 0.001, 100);
  const controls = new THREE.OrbitControls(camera, canvas);

  let mixer = null, action = null, duration = 0, playing = false, time = 0;
  let model = null;
  let selected = new Set();

  function render() {
    controls.update();
    renderer.render(scene, camera);
  }

  function meshesOf(name) {
    const node = model && model.getObjectByName(THREE.PropertyBinding.sanitizeNodeName(name));
    const meshes = [];
    if (node) node.traverse(function (o) { if (o.isMesh) meshes.push(o); });
    return meshes;
  }

  function stepAt(t) {
    for (let i = 0; i < data.steps.length; ++i) {
      if (t >= data.steps[i].start && t <= data.steps[i].end) return i;
    }
    return -1;
  }

  function captionAt(t) {
    const i = stepAt(t);
    if (i < 0) return t >= duration ? "Assembled" : "";
    const notes = data.findings.filter(function (f) {
      return f.step === i || (f.kind === "collision" && f.parts[0] === data.steps[i].parts[0]);
    });
    return "Step " + (i + 1) + " of " + data.steps.length + ": " + data.steps[i].label +
      notes.map(function (f) { return "\n[" + f.kind + "] " + f.message; }).join("");
  }

  function setTime(t) {
    time = Math.max(0, Math.min(duration, t));
    if (mixer) {
      action.time = time;
      mixer.update(0);
    }
    slider.value = duration > 0 ? Math.round(1000 * time / duration) : 0;
    clock.textContent = time.toFixed(1) + " / " + duration.toFixed(1) + " s";
    caption.textContent = captionAt(time);
  }

  // The camera looks at the box from its current side, far enough to hold it.
  function frame(box) {
    if (box.isEmpty()) return;
    const centre = box.getCenter(new THREE.Vector3());
    const size = Math.max(box.getSize(new THREE.Vector3()).length(), 0.02);
    const from = camera.position.clone().sub(controls.target);
    if (from.lengthSq() < 1e-12) from.set(1, 0.8, 1.2);
    from.setLength(0.55 * size / Math.sin(camera.fov * Math.PI / 360));  // the box's sphere in view
    controls.target.copy(centre);
    camera.position.copy(centre).add(from);
    camera.near = size / 100;
    camera.far = size * 100;
    camera.updateProjectionMatrix();
  }

  function boxOf(names) {
    const box = new THREE.Box3();
    names.forEach(function (name) {
      meshesOf(name).forEach(function (m) { box.expandByObject(m); });
    });
    return box;
  }

  function highlight(names) {
    selected = new Set(names);
    data.steps.forEach(function (s) {
      s.parts.forEach(function (name) {
        meshesOf(name).forEach(function (m) {
          if (m.material.emissive) m.material.emissive.setHex(selected.has(name) ? 0xd02000 : 0x000000);
        });
      });
    });
  }

  function overview() {
    highlight([]);
    setTime(duration);
    frame(new THREE.Box3().setFromObject(model));
    render();
  }

  // A finding: its step's end (or the finished product), its parts lit and framed.
  function show(index) {
    const f = data.findings[index];
    playing = false;
    playButton.textContent = "Play";
    const step = f.step >= 0 && f.step < data.steps.length ? data.steps[f.step] : null;
    setTime(step ? step.end : duration);
    const names = f.parts.filter(function (n) { return meshesOf(n).length > 0; });
    highlight(names);
    frame(names.length ? boxOf(names) : new THREE.Box3().setFromObject(model));
    render();
    document.querySelectorAll(".finding").forEach(function (li) {
      li.classList.toggle("selected", Number(li.dataset.finding) === index);
    });
  }

  document.querySelectorAll(".finding").forEach(function (li) {
    const open = function () { show(Number(li.dataset.finding)); };
    li.addEventListener("click", open);
    li.addEventListener("keydown", function (e) { if (e.key === "Enter") open(); });
  });
  playButton.addEventListener("click", function () {
    playing = !playing;
    if (playing && time >= duration) setTime(0);
    playButton.textContent = playing ? "Pause" : "Play";
  });
  slider.addEventListener("input", function () {
    playing = false;
    playButton.textContent = "Play";
    setTime(duration * slider.value / 1000);
    render();
  });
  document.getElementById("overview").addEventListener("click", overview);

  let last = null;
  function tick(now) {
    if (playing && last !== null && mixer) {
      setTime(time + (now - last) / 1000);
      if (time >= duration) {
        playing = false;
        playButton.textContent = "Play";
      }
    }
    last = now;
    render();
    requestAnimationFrame(tick);
  }

  new THREE.GLTFLoader().parse(document.getElementById("gltf").textContent, "", function (gltf) {
    model = gltf.scene;
    model.traverse(function (o) {
      if (o.isMesh) o.material = o.material.clone();  // each part lit on its own
    });
    scene.add(model);
    if (gltf.animations.length) {
      mixer = new THREE.AnimationMixer(model);
      action = mixer.clipAction(gltf.animations[0]);
      action.setLoop(THREE.LoopOnce);
      action.clampWhenFinished = true;
      action.play();
      duration = gltf.animations[0].duration;
    }
    // The finished product first, framed, on a floor grid its size; Play runs the assembly.
    setTime(duration);
    const box = new THREE.Box3().setFromObject(model);
    const size = Math.max(box.getSize(new THREE.Vector3()).length(), 0.05);
    const grid = new THREE.GridHelper(size * 3, 30, 0xa8adb4, 0xd4d7dc);
    grid.position.set(box.getCenter(new THREE.Vector3()).x, 0, box.getCenter(new THREE.Vector3()).z);
    scene.add(grid);
    frame(box);
    playButton.textContent = "Play";
    render();
    document.body.dataset.viewer = "ready";
    const video = /^#video=(\d+)$/.exec(location.hash);
    if (video) return record(Number(video[1]));
    requestAnimationFrame(tick);
  }, function (e) {
    fail("The 3D view could not be built: " + (e && e.message ? e.message : e));
  });

  // The caption of a video frame, in a box at its top left: the product, then the step.
  function drawCaption(g, text) {
    const lines = [document.querySelector("h1").textContent].concat(text ? text.split("\n") : []);
    const wrapped = [];
    g.font = "16px sans-serif";
    lines.forEach(function (line) {
      let rest = line;
      while (g.measureText(rest).width > canvas.width * 0.7 && rest.indexOf(" ") > 0) {
        let cut = rest.length;
        while (cut > 0 && g.measureText(rest.slice(0, cut)).width > canvas.width * 0.7) cut = rest.lastIndexOf(" ", cut - 1);
        if (cut <= 0) break;
        wrapped.push(rest.slice(0, cut));
        rest = rest.slice(cut + 1);
      }
      wrapped.push(rest);
    });
    const width = Math.max.apply(null, wrapped.map(function (l) { return g.measureText(l).width; }));
    g.fillStyle = "rgba(255, 255, 255, 0.85)";
    g.fillRect(8, 8, width + 16, wrapped.length * 21 + 10);
    g.fillStyle = "#1f2328";
    wrapped.forEach(function (line, i) { g.fillText(line, 16, 30 + i * 21); });
  }

  // #video=FPS: every frame of the animation, and a second of the finished product, as JPEGs
  // (base64, a line each) in <pre id="video-frames">, for cellctl plan --video.
  function record(fps) {
    const out = document.createElement("canvas");
    out.width = canvas.width;
    out.height = canvas.height;
    const g = out.getContext("2d");
    const count = Math.ceil(duration * fps) + fps;
    const frames = [];
    for (let i = 0; i < count; ++i) {
      const text = window.agileReport.frame(Math.min(duration, i / fps));
      g.drawImage(canvas, 0, 0);
      drawCaption(g, text);
      frames.push(out.toDataURL("image/jpeg", 0.9).replace(/^data:image\/jpeg;base64,/, ""));
    }
    const pre = document.createElement("pre");
    pre.id = "video-frames";
    pre.textContent = frames.join("\n");
    document.body.appendChild(pre);
  }

  // For a headless browser that records the animation: no clock of its own, a frame per call.
  window.agileReport = {
    duration: function () { return duration; },
    frame: function (t) {
      playing = false;
      setTime(t);
      render();
      return captionAt(t);
    },
    show: show,
  };
})();
