"""The deviation legend drawn over the 3D view: a colour bar with its tick values, in screen
space (its own orthographic camera), left out of the scene's bounding box so "fit all" frames
the blade, not the legend; above and below the bar, a swatch for each out-of-tolerance class
with its count. It draws the values and colours the DeviationMap object computed."""
from pivy import coin

from .i18n import translate

# Legend geometry in normalised view coordinates: the view spans [-1, 1] in x and in y
# whatever its aspect, so the legend keeps to the left edge in any window.
BAR_X = (-0.975, -0.945)
BAR_Y = (-0.75, 0.75)
LABEL_WIDTH = 0.25
# The labels are drawn in pixels while the backing is in view coordinates: at each render the
# backing is widened to the text's width in this view, taken as this many font sizes a
# character (FreeCAD's SoText2 font, measured generously) plus a margin in pixels.
CHAR_EM = 0.7
MARGIN_PX = 6
# The class swatches: their height and their gap from the bar, in view coordinates.
SWATCH_H = 0.05
SWATCH_GAP = 0.03


def _skip_bounding_group():
    """FreeCAD's SoSkipBoundingGroup keeps its children out of view-all's bounding box."""
    node_type = coin.SoType.fromName("SoSkipBoundingGroup")
    if node_type.isBad():
        return coin.SoSeparator()
    node = coin.cast(node_type.createInstance(), "SoGroup")
    return node


def legend_node(values, colours, title=None, font_size=14, above=None, below=None):
    """values (ascending, mm) with their colours (r, g, b in 0..1) -> a Coin node to add to a
    view provider's root; ``title`` default "Deviation [mm]", translated. ``above``,
    ``below``: (label, colour) of the out-of-tolerance classes, drawn as swatches over and
    under the bar (the node's ``class_labels`` lists their labels)."""
    if title is None:
        title = translate("BladeInspect", "Deviation [mm]")
    group = _skip_bounding_group()
    hud = coin.SoAnnotation()
    hud.renderCaching = coin.SoSeparator.OFF   # the backing follows the viewport (fit)
    group.addChild(hud)
    camera = coin.SoOrthographicCamera()
    camera.viewportMapping = coin.SoCamera.LEAVE_ALONE
    camera.aspectRatio = 1.0
    camera.height = 2.0
    camera.position = (0.0, 0.0, 5.0)
    camera.nearDistance = 1.0
    camera.farDistance = 10.0
    hud.addChild(camera)
    reset = coin.SoResetTransform()
    reset.whatToReset = coin.SoResetTransform.TRANSFORM
    hud.addChild(reset)
    light = coin.SoLightModel()
    light.model = coin.SoLightModel.BASE_COLOR
    hud.addChild(light)
    # The host view provider may draw its geometry as points (a point cloud's display mode):
    # the legend's quads must be filled whatever it chose.
    style = coin.SoDrawStyle()
    style.style = coin.SoDrawStyle.FILLED
    hud.addChild(style)
    pick = coin.SoPickStyle()
    pick.style = coin.SoPickStyle.UNPICKABLE
    hud.addChild(pick)
    if len(values) < 2:
        return group

    n = len(values)
    x0, x1 = BAR_X
    ys = [BAR_Y[0] + (BAR_Y[1] - BAR_Y[0]) * i / (n - 1) for i in range(n)]
    digits = 3 if max(abs(v) for v in values) < 1.0 else 2
    labels = ["%+.*f" % (digits, v) if abs(v) > 1e-12 else "%.*f" % (digits, 0.0)
              for v in values]
    swatches = [(y, label, colour) for y, cls in
                ((BAR_Y[1] + SWATCH_GAP, above), (BAR_Y[0] - SWATCH_GAP - SWATCH_H, below))
                if cls is not None for label, colour in (cls,)]
    group.class_labels = [label for _, label, _ in swatches]
    extra = SWATCH_GAP + SWATCH_H if swatches else 0.0
    title_y = BAR_Y[1] + 0.06 + extra
    backing, corners = _backing((x0 - 0.015, BAR_Y[0] - 0.06 - extra),
                                (x1 + LABEL_WIDTH, BAR_Y[1] + 0.12 + extra))
    # Each text's start (view x) and length in characters: the backing must reach past all.
    texts = [(x1 + 0.01, max(len(label) for label in labels + group.class_labels)),
             (x0, len(title))]
    group.fit_backing = _backing_fitter(corners, texts, font_size, x1 + LABEL_WIDTH)
    fit = coin.SoCallback()
    fit.setCallback(group.fit_backing)
    hud.addChild(fit)
    hud.addChild(backing)
    material = coin.SoMaterial()
    material.diffuseColor.setValues(0, 2 * n, [tuple(c) for c in colours for _ in (0, 1)])
    hud.addChild(material)
    binding = coin.SoMaterialBinding()
    binding.value = coin.SoMaterialBinding.PER_VERTEX_INDEXED
    hud.addChild(binding)
    coords = coin.SoCoordinate3()
    coords.point.setValues(0, 2 * n, [(x, y, 0.0) for y in ys for x in (x0, x1)])
    hud.addChild(coords)
    faces = coin.SoIndexedFaceSet()
    index = []
    for i in range(n - 1):
        index += [2 * i, 2 * i + 1, 2 * i + 3, 2 * i + 2, -1]
    faces.coordIndex.setValues(0, len(index), index)
    faces.materialIndex.setValues(0, len(index), index)
    hud.addChild(faces)
    for y, _, colour in swatches:
        hud.addChild(_swatch((x0, y), (x1, y + SWATCH_H), colour))

    overall = coin.SoMaterialBinding()
    overall.value = coin.SoMaterialBinding.OVERALL
    hud.addChild(overall)
    text_colour = coin.SoBaseColor()
    text_colour.rgb = (0.0, 0.0, 0.0)
    hud.addChild(text_colour)
    font = coin.SoFont()
    font.size = font_size
    hud.addChild(font)
    for label, y in zip(labels, ys):
        hud.addChild(_text((x1 + 0.01, y - 0.015, 0.0), label))
    for y, label, _ in swatches:
        hud.addChild(_text((x1 + 0.01, y + 0.5 * SWATCH_H - 0.015, 0.0), label))
    hud.addChild(_text((x0, title_y, 0.0), title))
    return group


def _backing_fitter(corners, texts, font_size, least_right):
    """A SoCallback function that moves the right edge of the backing ``corners`` (its
    SoCoordinate3) past every text (start in view x, length in characters) in the viewport
    being rendered, and never left of ``least_right``."""
    def fit(_, action):
        if not action.isOfType(coin.SoGLRenderAction.getClassTypeId()):
            return
        region = coin.SoViewportRegionElement.get(action.getState())
        width_px = region.getViewportSizePixels().getValue()[0]
        if width_px <= 0:
            return
        per_px = 2.0 / width_px     # the view spans 2 in x
        right = max([least_right] + [x + (n * CHAR_EM * font_size + MARGIN_PX) * per_px
                                     for x, n in texts])
        points = [tuple(p.getValue()) for p in corners.point.getValues()]
        if abs(points[1][0] - right) > 1e-9:
            # Not a scene change for the viewer to redraw: this render draws it already.
            corners.point.enableNotify(False)
            for k in (1, 2):
                corners.point.set1Value(k, (right, points[k][1], points[k][2]))
            corners.point.enableNotify(True)
    return fit


def _backing(lower_left, upper_right):
    """A pale panel behind the legend so its labels read on any background: (its separator,
    its SoCoordinate3, corners lower-left, lower-right, upper-right, upper-left)."""
    sep = coin.SoSeparator()
    sep.renderCaching = coin.SoSeparator.OFF   # its corners follow the viewport (fit)
    binding = coin.SoMaterialBinding()
    binding.value = coin.SoMaterialBinding.OVERALL   # not the host's per-point colours
    sep.addChild(binding)
    colour = coin.SoBaseColor()
    colour.rgb = (0.97, 0.97, 0.97)
    sep.addChild(colour)
    (xa, ya), (xb, yb) = lower_left, upper_right
    coords = coin.SoCoordinate3()
    coords.point.setValues(0, 4, [(xa, ya, -0.01), (xb, ya, -0.01), (xb, yb, -0.01),
                                  (xa, yb, -0.01)])
    sep.addChild(coords)
    face = coin.SoFaceSet()
    face.numVertices.setValue(4)
    sep.addChild(face)
    return sep, coords


def _swatch(lower_left, upper_right, colour):
    """A filled rectangle of one colour."""
    sep = coin.SoSeparator()
    binding = coin.SoMaterialBinding()
    binding.value = coin.SoMaterialBinding.OVERALL
    sep.addChild(binding)
    base = coin.SoBaseColor()
    base.rgb = tuple(colour)
    sep.addChild(base)
    (xa, ya), (xb, yb) = lower_left, upper_right
    coords = coin.SoCoordinate3()
    coords.point.setValues(0, 4, [(xa, ya, 0.0), (xb, ya, 0.0), (xb, yb, 0.0), (xa, yb, 0.0)])
    sep.addChild(coords)
    face = coin.SoFaceSet()
    face.numVertices.setValue(4)
    sep.addChild(face)
    return sep


def _text(position, text):
    sep = coin.SoSeparator()
    move = coin.SoTranslation()
    move.translation = position
    sep.addChild(move)
    label = coin.SoText2()
    label.string = text
    sep.addChild(label)
    return sep
