// Measures a loaded page for the browser test and returns plain JSON:
// the images that did not load, the SVGs laid out with no area, and where
// the page passes the window's right edge. Elements inside a box that
// scrolls sideways by itself may pass it; the box itself may not.
(async () => {
  if (document.readyState !== "complete") {
    await new Promise((loaded) => addEventListener("load", loaded, { once: true }));
  }
  const describe = (element) => {
    const id = element.id ? `#${element.id}` : "";
    const classes = [...element.classList].map((name) => `.${name}`).join("");
    const text = (element.textContent || "").trim().replace(/\s+/g, " ").slice(0, 60);
    return `<${element.tagName.toLowerCase()}${id}${classes}> "${text}"`;
  };
  const hasNoArea = (element) => {
    const box = element.getBoundingClientRect();
    return box.width === 0 || box.height === 0;
  };
  const images = [...document.images];
  const isSvgImage = (image) =>
    /\.svg([?#]|$)/i.test(image.src) || image.src.startsWith("data:image/svg+xml");
  const scrollsItself = (element) => ["auto", "scroll"].includes(getComputedStyle(element).overflowX);
  const insideScrollingBox = (element) => {
    for (let box = element.parentElement; box && box !== document.body; box = box.parentElement) {
      if (scrollsItself(box)) return true;
    }
    return false;
  };
  const windowWidth = document.documentElement.clientWidth;
  const overflowing = [];
  for (const element of document.body.querySelectorAll("*")) {
    if (element.getBoundingClientRect().right <= windowWidth) continue;
    if (insideScrollingBox(element)) continue;
    // Document order puts a box before its contents: report the outermost only.
    if (overflowing.some((outer) => outer.contains(element))) continue;
    overflowing.push(element);
  }
  return {
    windowWidth,
    pageWidth: document.documentElement.scrollWidth,
    imagesNotLoaded: images
      .filter((image) => image.naturalWidth === 0 || image.naturalHeight === 0)
      .map((image) => image.src),
    emptySvgs: [...document.querySelectorAll("svg"), ...images.filter(isSvgImage)]
      .filter(hasNoArea)
      .map(describe),
    overflowing: overflowing.map(
      (element) => `${describe(element)} ends at ${element.getBoundingClientRect().right}px`,
    ),
  };
})()
