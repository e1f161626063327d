// What the viewer draws for a motion (no three.js here: the UI's link and attribute checks import it).

/** The stick figure, the character, or both (the skeleton seen through a see-through character). */
export type Look = 'skeleton' | 'character' | 'both';
export const LOOKS: readonly Look[] = ['skeleton', 'character', 'both'];
export const DEFAULT_LOOK: Look = 'character';
